// One swapped pair, not a face order: float maths throughout, and the face
// index for z is chosen with the sign the wrong way round, so +Z directions
// read the -Z face and -Z directions the +Z face, at the right (u, v). The
// other four faces are right. readTexture is the handout's.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    const float x = (float)d.x, y = (float)d.y, z = (float)d.z;
    const float ax = std::fabs(x), ay = std::fabs(y), az = std::fabs(z);
    int face;
    float u, v;
    if (ax >= ay && ax >= az) {
        face = x > 0 ? FACE_POS_X : FACE_NEG_X;
        u = 0.5f + 0.5f * (x > 0 ? z : -z) / ax;
        v = 0.5f + 0.5f * y / ax;
    } else if (ay >= az) {
        face = y > 0 ? FACE_POS_Y : FACE_NEG_Y;
        u = 0.5f + 0.5f * x / ay;
        v = 0.5f + 0.5f * (y > 0 ? z : -z) / ay;
    } else {
        face = z < 0 ? FACE_POS_Z : FACE_NEG_Z;      // the sign the wrong way round
        u = 0.5f + 0.5f * x / az;
        v = 0.5f + 0.5f * (z > 0 ? -y : y) / az;
    }
    return readTexture(faceAddress(face), u, v);
}

// readTexture:begin
Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const double px = u * m_FaceWidth, py = v * m_FaceHeight;
    const int x0 = std::clamp((int)px, 0, m_FaceWidth - 1), y0 = std::clamp((int)py, 0, m_FaceHeight - 1);
    const int x1 = std::min(x0 + 1, m_FaceWidth - 1), y1 = std::min(y0 + 1, m_FaceHeight - 1);
    const double a = px - (int)px, b = py - (int)py;
    auto at = [&](int x, int y) { const float* p = addr + 3 * (y * m_FaceWidth + x); return Color(p[0], p[1], p[2]); };
    return (1 - b) * ((1 - a) * at(x0, y0) + a * at(x1, y0)) + b * ((1 - a) * at(x0, y1) + a * at(x1, y1));
}
// readTexture:end
