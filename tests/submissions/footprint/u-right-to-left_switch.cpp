// The handout's bilinear at (1 - u, v): u runs from the right. fetchColor
// is right (the flip is in readTexture only).
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
    const double px = (1.0 - u) * W, py = v * H;
    const int x0 = std::clamp((int)px, 0, W - 1), y0 = std::clamp((int)py, 0, H - 1);
    const int x1 = std::min(x0 + 1, W - 1), y1 = std::min(y0 + 1, H - 1);
    const double a = px - (int)px, b = py - (int)py;
    const float *p00 = &addr[3 * (y0 * W + x0)], *p10 = &addr[3 * (y0 * W + x1)];
    const float *p01 = &addr[3 * (y1 * W + x0)], *p11 = &addr[3 * (y1 * W + x1)];
    const Color c00(p00[0], p00[1], p00[2]), c10(p10[0], p10[1], p10[2]);
    const Color c01(p01[0], p01[1], p01[2]), c11(p11[0], p11[1], p11[2]);
    return (c00 * (1 - a) + c10 * a) * (1 - b) + (c01 * (1 - a) + c11 * a) * b;
}
// readTexture:end
