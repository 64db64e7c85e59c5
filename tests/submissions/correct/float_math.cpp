// A correct solution that computes in float rather than double: it matches
// the reference only to float precision (about 1e-7 relative in u and v).
// It scales the direction by its largest component in double first, so
// directions beyond float's range (1e-310, 1e300) still work.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    const double m = std::max(std::fabs(direction.x), std::max(std::fabs(direction.y), std::fabs(direction.z)));
    if (!(m > 0) || !std::isfinite(m))
        return Color(0, 0, 0);
    const float x = (float)(direction.x / m), y = (float)(direction.y / m), z = (float)(direction.z / m);
    const float ax = std::fabs(x), ay = std::fabs(y), az = std::fabs(z);
    int face;
    float u, v;
    if (ax >= ay && ax >= az) {
        face = x > 0 ? FACE_POS_X : FACE_NEG_X;
        u = 0.5f * (1.0f + (x > 0 ? z : -z) / ax);
        v = 0.5f * (1.0f + y / ax);
    } else if (ay >= az) {
        face = y > 0 ? FACE_POS_Y : FACE_NEG_Y;
        u = 0.5f * (1.0f + x / ay);
        v = 0.5f * (1.0f + (y > 0 ? z : -z) / ay);
    } else {
        face = z > 0 ? FACE_POS_Z : FACE_NEG_Z;
        u = 0.5f * (1.0f + x / az);
        v = 0.5f * (1.0f + (z > 0 ? -y : y) / az);
    }
    return readTexture(faceAddress(face), u, v);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const float px = (float)u * m_FaceWidth, py = (float)v * m_FaceHeight;
    const int ix = (int)px, iy = (int)py;
    const float alpha = px - ix, beta = py - iy;
    const int x0 = std::min(std::max(ix, 0), m_FaceWidth - 1);
    const int x1 = std::min(std::max(ix + 1, 0), m_FaceWidth - 1);
    const int y0 = std::min(std::max(iy, 0), m_FaceHeight - 1);
    const int y1 = std::min(std::max(iy + 1, 0), m_FaceHeight - 1);
    float rgb[3];
    for (int k = 0; k < 3; ++k) {
        const float c00 = addr[3 * (y0 * m_FaceWidth + x0) + k];
        const float c10 = addr[3 * (y0 * m_FaceWidth + x1) + k];
        const float c01 = addr[3 * (y1 * m_FaceWidth + x0) + k];
        const float c11 = addr[3 * (y1 * m_FaceWidth + x1) + k];
        const float c0 = (1.0f - alpha) * c00 + alpha * c10;
        const float c1 = (1.0f - alpha) * c01 + alpha * c11;
        rgb[k] = (1.0f - beta) * c0 + beta * c1;
    }
    return Color(rgb[0], rgb[1], rgb[2]);
}
