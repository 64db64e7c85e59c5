// Issue 29, pattern 12: the handout's bilinear, with the face size read once
// into statics at the first call. Right as long as the face never changes
// size in the process; after another size it indexes with the old one.
// fetchColor is right.
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
    static const int W = m_FaceWidth;      // the size cannot change: read it once
    static const int H = m_FaceHeight;
    const double px = u * W, py = v * H;
    const int x0 = std::max(0, std::min((int)px, W - 1)), y0 = std::max(0, std::min((int)py, H - 1));
    const int x1 = std::min(x0 + 1, W - 1), y1 = std::min(y0 + 1, H - 1);
    const double a = px - (int)px, b = py - (int)py;
    const float* t00 = addr + 3 * (y0 * W + x0);
    const float* t10 = addr + 3 * (y0 * W + x1);
    const float* t01 = addr + 3 * (y1 * W + x0);
    const float* t11 = addr + 3 * (y1 * W + x1);
    Color out;
    out.r = (1 - b) * ((1 - a) * t00[0] + a * t10[0]) + b * ((1 - a) * t01[0] + a * t11[0]);
    out.g = (1 - b) * ((1 - a) * t00[1] + a * t10[1]) + b * ((1 - a) * t01[1] + a * t11[1]);
    out.b = (1 - b) * ((1 - a) * t00[2] + a * t10[2]) + b * ((1 - a) * t01[2] + a * t11[2]);
    return out;
}
// readTexture:end
