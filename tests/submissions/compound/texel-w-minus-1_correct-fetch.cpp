// Compound zoo. fetchColor: correct (if-chain). readTexture: returns the one
// texel (int(u(W-1)), int(v(H-1))): no blending, and the lattice scaled by
// W - 1 instead of W.
#include "EnvironmentMap.h"

#include <cmath>

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    double x = direction.x, y = direction.y, z = direction.z;
    double ax = std::fabs(x), ay = std::fabs(y), az = std::fabs(z);
    if (ax >= ay && ax >= az) {
        if (x > 0) return readTexture(faceAddress(FACE_POS_X), (1 + z / ax) / 2, (1 + y / ax) / 2);
        return readTexture(faceAddress(FACE_NEG_X), (1 - z / ax) / 2, (1 + y / ax) / 2);
    }
    if (ay >= az) {
        if (y > 0) return readTexture(faceAddress(FACE_POS_Y), (1 + x / ay) / 2, (1 + z / ay) / 2);
        return readTexture(faceAddress(FACE_NEG_Y), (1 + x / ay) / 2, (1 - z / ay) / 2);
    }
    if (z > 0) return readTexture(faceAddress(FACE_POS_Z), (1 + x / az) / 2, (1 - y / az) / 2);
    return readTexture(faceAddress(FACE_NEG_Z), (1 + x / az) / 2, (1 + y / az) / 2);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    int x = (int)(u * (m_FaceWidth - 1));
    int y = (int)(v * (m_FaceHeight - 1));
    const float* t = addr + 3 * (y * m_FaceWidth + x);
    return Color(t[0], t[1], t[2]);
}
