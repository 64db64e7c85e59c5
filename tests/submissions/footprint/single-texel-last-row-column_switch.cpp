// Issue 29, pattern 4: the handout's bilinear, except that in the last row
// and the last column it returns the texel (x0, y0) alone, also blending
// nothing along the other axis. No catalogue id says this: the report shows
// it in numbers. fetchColor is right.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

Color EnvironmentMap::fetchColor(const Vector3& dir) const
{
    const double ax = std::abs(dir.x), ay = std::abs(dir.y), az = std::abs(dir.z);
    const int axis = (ax >= ay && ax >= az) ? 0 : (ay >= az ? 1 : 2);
    const double m = axis == 0 ? ax : axis == 1 ? ay : az;
    if (!(m > 0) || std::isinf(m) || std::isnan(dir.x + dir.y + dir.z))
        return Color(0, 0, 0);
    const double x = dir.x / m, y = dir.y / m, z = dir.z / m;
    int face;
    double u, v;
    switch (axis) {
    case 0:
        face = x > 0 ? FACE_POS_X : FACE_NEG_X;
        u = (1 + (x > 0 ? z : -z)) / 2;
        v = (1 + y) / 2;
        break;
    case 1:
        face = y > 0 ? FACE_POS_Y : FACE_NEG_Y;
        u = (1 + x) / 2;
        v = (1 + (y > 0 ? z : -z)) / 2;
        break;
    default:
        face = z > 0 ? FACE_POS_Z : FACE_NEG_Z;
        u = (1 + x) / 2;
        v = (1 + (z > 0 ? -y : y)) / 2;
        break;
    }
    return readTexture(faceAddress(face), u, v);
}

// readTexture:begin
Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const int W = m_FaceWidth, H = m_FaceHeight;
    const double px = u * W, py = v * H;
    const int x0 = std::min((int)px, W - 1), y0 = std::min((int)py, H - 1);
    auto at = [=](int x, int y) { const float* t = addr + 3 * (y * W + x); return Color(t[0], t[1], t[2]); };
    if (x0 == W - 1 || y0 == H - 1)        // no neighbour to the right or above
        return at(x0, y0);
    const double a = px - x0, b = py - y0;
    const Color c0 = at(x0, y0) * (1 - a) + at(x0 + 1, y0) * a;
    const Color c1 = at(x0, y0 + 1) * (1 - a) + at(x0 + 1, y0 + 1) * a;
    return c0 * (1 - b) + c1 * b;
}
// readTexture:end
