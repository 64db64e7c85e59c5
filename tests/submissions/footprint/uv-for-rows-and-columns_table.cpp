// x from v and y from u (each scaled by its own axis's size): u picks the
// row, v the column. fetchColor is right.
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
    const double col = v * W, row = u * H;
    const int x0 = std::clamp((int)std::floor(col), 0, W - 1), x1 = std::min(x0 + 1, W - 1);
    const int y0 = std::clamp((int)std::floor(row), 0, H - 1), y1 = std::min(y0 + 1, H - 1);
    const double s = col - std::floor(col), t = row - std::floor(row);
    auto px = [&](int x, int y) { return Color(addr[3 * (y * W + x)], addr[3 * (y * W + x) + 1], addr[3 * (y * W + x) + 2]); };
    return (px(x0, y0) * (1 - s) + px(x1, y0) * s) * (1 - t) + (px(x0, y1) * (1 - s) + px(x1, y1) * s) * t;
}
// readTexture:end
