// Nearest texel at floor((W - 1) u), rows counted from the top
// (y = H - 1 - floor((H - 1) v)). fetchColor (float (u, v), a switch) is right.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    // The face picked by a switch on the major axis; (u, v) in float once the
    // components are divided by m (float cannot hold every length, a ratio it can).
    const double ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
    const double m = std::max(ax, std::max(ay, az));
    if (!(m > 0) || !std::isfinite(m) || std::isnan(d.x + d.y + d.z))
        return Color();                 // no face: any colour will do
    const float x = (float)(d.x / m), y = (float)(d.y / m), z = (float)(d.z / m);
    const int major = (ax >= ay && ax >= az) ? 0 : (ay >= az ? 1 : 2);
    float u = 0, v = 0;
    int face = 0;
    switch (major) {
    case 0: face = x > 0 ? FACE_POS_X : FACE_NEG_X; u = 0.5f * (1 + (x > 0 ? z : -z)); v = 0.5f * (1 + y); break;
    case 1: face = y > 0 ? FACE_POS_Y : FACE_NEG_Y; u = 0.5f * (1 + x); v = 0.5f * (1 + (y > 0 ? z : -z)); break;
    default: face = z > 0 ? FACE_POS_Z : FACE_NEG_Z; u = 0.5f * (1 + x); v = 0.5f * (1 + (z > 0 ? -y : y)); break;
    }
    
    return readTexture(faceAddress(face), u, v);
}

// readTexture:begin
Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const int x = (int)std::floor((m_FaceWidth - 1) * u);
    const int y = m_FaceHeight - 1 - (int)std::floor((m_FaceHeight - 1) * v);
    const float* p = addr + 3 * (std::clamp(y, 0, m_FaceHeight - 1) * m_FaceWidth + std::clamp(x, 0, m_FaceWidth - 1));
    return Color(p[0], p[1], p[2]);
}
// readTexture:end
