// Compound zoo. fetchColor: correct (signed major components). readTexture:
// bilinear at p = (uW - 1, vH - 1), clamped, so it reads one texel left and
// below.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    const double x = d.x, y = d.y, z = d.z;
    const double ax = std::fabs(x), ay = std::fabs(y), az = std::fabs(z);
    if (x >= ay && x >= az && x > 0)   return readTexture(faceAddress(FACE_POS_X), (1 + z / x) / 2, (1 + y / x) / 2);
    if (-x >= ay && -x >= az && x < 0) return readTexture(faceAddress(FACE_NEG_X), (1 + z / x) / 2, (1 - y / x) / 2);
    if (y >= az && y > 0)              return readTexture(faceAddress(FACE_POS_Y), (1 + x / y) / 2, (1 + z / y) / 2);
    if (-y >= az && y < 0)             return readTexture(faceAddress(FACE_NEG_Y), (1 - x / y) / 2, (1 + z / y) / 2);
    if (z > 0)                         return readTexture(faceAddress(FACE_POS_Z), (1 + x / z) / 2, (1 - y / z) / 2);
    return readTexture(faceAddress(FACE_NEG_Z), (1 - x / z) / 2, (1 - y / z) / 2);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const double px = u * m_FaceWidth - 1.0, py = v * m_FaceHeight - 1.0;
    const double fx = std::floor(px), fy = std::floor(py);
    const double alpha = px - fx, beta = py - fy;
    const int x0 = std::clamp((int)fx, 0, m_FaceWidth - 1), x1 = std::clamp((int)fx + 1, 0, m_FaceWidth - 1);
    const int y0 = std::clamp((int)fy, 0, m_FaceHeight - 1), y1 = std::clamp((int)fy + 1, 0, m_FaceHeight - 1);
    auto at = [&](int x, int y) { const float* t = addr + 3 * (y * m_FaceWidth + x); return Color(t[0], t[1], t[2]); };
    return (1 - beta) * ((1 - alpha) * at(x0, y0) + alpha * at(x1, y0)) + beta * ((1 - alpha) * at(x0, y1) + alpha * at(x1, y1));
}
