// Issue 29, pattern 3: a 2x2 box filter, a quarter to each texel whatever p
// is, rows counted from the top, and x0 held at W - 2 so that x0 + 1 stays on
// the face (an edge shift on x only). fetchColor is right.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

namespace {
// One row per face: the major axis and its sign, then u and v as
// (1 + sign * component / m) / 2 (README.md's table).
struct FaceRow { int face, axis; double sign; int uAxis; double uSign; int vAxis; double vSign; };
const FaceRow kFaces[6] = {
    {FACE_POS_X, 0, +1, 2, +1, 1, +1},
    {FACE_NEG_X, 0, -1, 2, -1, 1, +1},
    {FACE_POS_Y, 1, +1, 0, +1, 2, +1},
    {FACE_NEG_Y, 1, -1, 0, +1, 2, -1},
    {FACE_POS_Z, 2, +1, 0, +1, 1, -1},
    {FACE_NEG_Z, 2, -1, 0, +1, 1, +1},
};
}

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    const double c[3] = {direction.x, direction.y, direction.z};
    int major = 0;
    for (int a = 1; a < 3; ++a)
        if (std::fabs(c[a]) > std::fabs(c[major]))
            major = a;
    const double m = std::fabs(c[major]);
    if (!(m > 0) || !std::isfinite(m) || std::isnan(c[0] + c[1] + c[2]))
        return Color();
    const FaceRow& f = kFaces[2 * major + (c[major] < 0 ? 1 : 0)];
    const double u = 0.5 * (1 + f.uSign * c[f.uAxis] / m);
    const double v = 0.5 * (1 + f.vSign * c[f.vAxis] / m);
    return readTexture(faceAddress(f.face), u, v);
}

// readTexture:begin
Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const int W = m_FaceWidth, H = m_FaceHeight;
    int x0 = (int)(u * W), y0 = (int)(v * H);
    x0 = std::min(x0, W - 2);              // its right neighbour must exist
    y0 = std::min(y0, H - 1);
    const int y1 = std::min(y0 + 1, H - 1);
    auto texel = [&](int x, int y) {
        const float* t = addr + 3 * ((H - 1 - y) * W + x);   // row 0 is the top row
        return Color(t[0], t[1], t[2]);
    };
    return (texel(x0, y0) + texel(x0 + 1, y0) + texel(x0, y1) + texel(x0 + 1, y1)) * 0.25;
}
// readTexture:end
