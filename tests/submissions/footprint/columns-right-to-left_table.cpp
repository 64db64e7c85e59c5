// The handout's bilinear, with the column counted from the right:
// addr[3 * (y * W + (W - 1 - x))]. fetchColor is right.
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
static Color texelAt(const float* addr, int W, int x, int y)
{
    const float* t = addr + 3 * (y * W + (W - 1 - x));
    return Color(t[0], t[1], t[2]);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const int W = m_FaceWidth, H = m_FaceHeight;
    const double px = u * W, py = v * H;
    const int x0 = std::min((int)px, W - 1), y0 = std::min((int)py, H - 1);
    const int x1 = std::min(x0 + 1, W - 1), y1 = std::min(y0 + 1, H - 1);
    const double a = px - (int)px, b = py - (int)py;
    return (texelAt(addr, W, x0, y0) * (1 - a) + texelAt(addr, W, x1, y0) * a) * (1 - b)
         + (texelAt(addr, W, x0, y1) * (1 - a) + texelAt(addr, W, x1, y1) * a) * b;
}
// readTexture:end
