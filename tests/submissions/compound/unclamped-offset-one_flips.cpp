// Compound zoo. fetchColor (if-chain): u runs the wrong way on +X, v the wrong
// way on -Z. readTexture: bilinear at p = (uW - 1, vH - 1), one texel left and
// below, with no clamp: x0 = -1 reads before the row (or the face), x1 = W-1+1 never.
#include "EnvironmentMap.h"

#include <cmath>

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    const double x = direction.x, y = direction.y, z = direction.z;
    const double ax = std::fabs(x), ay = std::fabs(y), az = std::fabs(z);
    int face;
    double u, v;
    if (ax >= ay && ax >= az) {
        if (x > 0) { face = FACE_POS_X; u = (1 - z / ax) / 2; v = (1 + y / ax) / 2; }   // u flipped
        else       { face = FACE_NEG_X; u = (1 - z / ax) / 2; v = (1 + y / ax) / 2; }
    } else if (ay >= az) {
        if (y > 0) { face = FACE_POS_Y; u = (1 + x / ay) / 2; v = (1 + z / ay) / 2; }
        else       { face = FACE_NEG_Y; u = (1 + x / ay) / 2; v = (1 - z / ay) / 2; }
    } else {
        if (z > 0) { face = FACE_POS_Z; u = (1 + x / az) / 2; v = (1 - y / az) / 2; }
        else       { face = FACE_NEG_Z; u = (1 + x / az) / 2; v = (1 - y / az) / 2; }     // v flipped
    }
    return readTexture(faceAddress(face), u, v);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const double px = u * m_FaceWidth - 1, py = v * m_FaceHeight - 1;
    const int x0 = (int)std::floor(px), y0 = (int)std::floor(py);
    const double alpha = px - x0, beta = py - y0;
    const int x1 = x0 + 1, y1 = y0 + 1;
    const int W = m_FaceWidth;
    Color c00(addr[3 * (y0 * W + x0)], addr[3 * (y0 * W + x0) + 1], addr[3 * (y0 * W + x0) + 2]);
    Color c10(addr[3 * (y0 * W + x1)], addr[3 * (y0 * W + x1) + 1], addr[3 * (y0 * W + x1) + 2]);
    Color c01(addr[3 * (y1 * W + x0)], addr[3 * (y1 * W + x0) + 1], addr[3 * (y1 * W + x0) + 2]);
    Color c11(addr[3 * (y1 * W + x1)], addr[3 * (y1 * W + x1) + 1], addr[3 * (y1 * W + x1) + 2]);
    Color c0 = (1 - alpha) * c00 + alpha * c10;
    Color c1 = (1 - alpha) * c01 + alpha * c11;
    return (1 - beta) * c0 + beta * c1;
}
