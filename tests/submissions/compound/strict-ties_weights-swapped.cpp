// Compound zoo. fetchColor (if-chain with strict comparisons): a direction
// where |x| ties |y| (or another pair) as the largest fails both strict tests
// and falls through to the z face, which it does not touch. readTexture:
// alpha and beta swapped: (alpha) c00 + (1 - alpha) c10.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    const double x = direction.x, y = direction.y, z = direction.z;
    const double ax = std::fabs(x), ay = std::fabs(y), az = std::fabs(z);
    if (ax > ay && ax > az) {
        if (x > 0) return readTexture(faceAddress(FACE_POS_X), (1 + z / ax) / 2, (1 + y / ax) / 2);
        return readTexture(faceAddress(FACE_NEG_X), (1 - z / ax) / 2, (1 + y / ax) / 2);
    } else if (ay > ax && ay > az) {
        if (y > 0) return readTexture(faceAddress(FACE_POS_Y), (1 + x / ay) / 2, (1 + z / ay) / 2);
        return readTexture(faceAddress(FACE_NEG_Y), (1 + x / ay) / 2, (1 - z / ay) / 2);
    } else {
        if (z > 0) return readTexture(faceAddress(FACE_POS_Z), (1 + x / az) / 2, (1 - y / az) / 2);
        return readTexture(faceAddress(FACE_NEG_Z), (1 + x / az) / 2, (1 + y / az) / 2);
    }
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const double px = u * m_FaceWidth, py = v * m_FaceHeight;
    const int xf = (int)px, yf = (int)py;
    const double alpha = px - xf, beta = py - yf;
    const int x0 = std::min(xf, m_FaceWidth - 1), x1 = std::min(xf + 1, m_FaceWidth - 1);
    const int y0 = std::min(yf, m_FaceHeight - 1), y1 = std::min(yf + 1, m_FaceHeight - 1);
    double c[3];
    for (int k = 0; k < 3; ++k) {
        const double c0 = alpha * addr[3 * (y0 * m_FaceWidth + x0) + k] + (1 - alpha) * addr[3 * (y0 * m_FaceWidth + x1) + k];
        const double c1 = alpha * addr[3 * (y1 * m_FaceWidth + x0) + k] + (1 - alpha) * addr[3 * (y1 * m_FaceWidth + x1) + k];
        c[k] = beta * c0 + (1 - beta) * c1;
    }
    return Color(c[0], c[1], c[2]);
}
