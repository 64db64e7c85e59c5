// Compound zoo. fetchColor (if-chain) converts the components to float first:
// tiny components (|d| < 1e-38) lose their precision or become 0 (then 0/0),
// huge ones (> 3e38) become infinite. readTexture: the starting code without
// its clamp: (int)(u*W) is W at u = 1, which reads the next row or past the face.
#include "EnvironmentMap.h"

#include <cmath>

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    float x = direction.x, y = direction.y, z = direction.z;
    float ax = std::fabs(x), ay = std::fabs(y), az = std::fabs(z);
    if (ax >= ay && ax >= az) {
        if (x > 0) return readTexture(faceAddress(FACE_POS_X), (1 + z / ax) / 2, (1 + y / ax) / 2);
        else return readTexture(faceAddress(FACE_NEG_X), (1 - z / ax) / 2, (1 + y / ax) / 2);
    } else if (ay >= az) {
        if (y > 0) return readTexture(faceAddress(FACE_POS_Y), (1 + x / ay) / 2, (1 + z / ay) / 2);
        else return readTexture(faceAddress(FACE_NEG_Y), (1 + x / ay) / 2, (1 - z / ay) / 2);
    } else {
        if (z > 0) return readTexture(faceAddress(FACE_POS_Z), (1 + x / az) / 2, (1 - y / az) / 2);
        else return readTexture(faceAddress(FACE_NEG_Z), (1 + x / az) / 2, (1 + y / az) / 2);
    }
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    int x0 = (int)(u * m_FaceWidth);
    int y0 = (int)(v * m_FaceHeight);
    const float* t = &addr[3 * (y0 * m_FaceWidth + x0)];
    return Color(t[0], t[1], t[2]);
}
