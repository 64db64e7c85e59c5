// Compound zoo. fetchColor normalises the direction first: x*x + y*y + z*z
// overflows to infinity for |d| > 1e154 (every component becomes 0, then 0/0)
// and underflows to 0 for |d| < 1e-154. readTexture: half a texel off,
// p = (uW - 0.5, vH - 0.5), floored and clamped.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    const double len = std::sqrt(direction.x * direction.x + direction.y * direction.y + direction.z * direction.z);
    const double x = direction.x / len, y = direction.y / len, z = direction.z / len;
    const double ax = std::fabs(x), ay = std::fabs(y), az = std::fabs(z);
    int face;
    double u, v;
    if (ax >= ay && ax >= az) {
        face = x > 0 ? FACE_POS_X : FACE_NEG_X;
        u = (1 + (x > 0 ? z : -z) / ax) / 2;
        v = (1 + y / ax) / 2;
    } else if (ay >= az) {
        face = y > 0 ? FACE_POS_Y : FACE_NEG_Y;
        u = (1 + x / ay) / 2;
        v = (1 + (y > 0 ? z : -z) / ay) / 2;
    } else {
        face = z > 0 ? FACE_POS_Z : FACE_NEG_Z;
        u = (1 + x / az) / 2;
        v = (1 + (z > 0 ? -y : y) / az) / 2;
    }
    return readTexture(faceAddress(face), u, v);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const double px = u * m_FaceWidth - 0.5, py = v * m_FaceHeight - 0.5;
    const double fx = std::floor(px), fy = std::floor(py);
    const double alpha = px - fx, beta = py - fy;
    const int x0 = std::max(0, std::min((int)fx, m_FaceWidth - 1)), x1 = std::max(0, std::min((int)fx + 1, m_FaceWidth - 1));
    const int y0 = std::max(0, std::min((int)fy, m_FaceHeight - 1)), y1 = std::max(0, std::min((int)fy + 1, m_FaceHeight - 1));
    double c[3];
    for (int k = 0; k < 3; ++k) {
        const double c0 = (1 - alpha) * addr[3 * (y0 * m_FaceWidth + x0) + k] + alpha * addr[3 * (y0 * m_FaceWidth + x1) + k];
        const double c1 = (1 - alpha) * addr[3 * (y1 * m_FaceWidth + x0) + k] + alpha * addr[3 * (y1 * m_FaceWidth + x1) + k];
        c[k] = (1 - beta) * c0 + beta * c1;
    }
    return Color(c[0], c[1], c[2]);
}
