// Issue 29, pattern 1: the nearest texel by rounding u (W - 1): no blend,
// the lattice scaled by W - 1, and no 0.5 anywhere. fetchColor is right.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    const double ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
    const double m = std::max(ax, std::max(ay, az));
    if (!(m > 0) || !std::isfinite(m) || std::isnan(d.x + d.y + d.z))
        return Color();                       // no face to read
    const double x = d.x / m, y = d.y / m, z = d.z / m;
    if (ax >= ay && ax >= az) {
        if (x > 0)
            return readTexture(faceAddress(FACE_POS_X), 0.5 * (1 + z), 0.5 * (1 + y));
        return readTexture(faceAddress(FACE_NEG_X), 0.5 * (1 - z), 0.5 * (1 + y));
    }
    if (ay >= az) {
        if (y > 0)
            return readTexture(faceAddress(FACE_POS_Y), 0.5 * (1 + x), 0.5 * (1 + z));
        return readTexture(faceAddress(FACE_NEG_Y), 0.5 * (1 + x), 0.5 * (1 - z));
    }
    if (z > 0)
        return readTexture(faceAddress(FACE_POS_Z), 0.5 * (1 + x), 0.5 * (1 - y));
    return readTexture(faceAddress(FACE_NEG_Z), 0.5 * (1 + x), 0.5 * (1 + y));
}

// readTexture:begin
Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    // The texel nearest to (u, v) when texel 0 sits at u = 0 and texel W-1 at u = 1.
    const int x = (int)std::round(u * (m_FaceWidth - 1));
    const int y = (int)std::round(v * (m_FaceHeight - 1));
    const float* t = addr + 3 * (y * m_FaceWidth + x);
    return Color(t[0], t[1], t[2]);
}
// readTexture:end
