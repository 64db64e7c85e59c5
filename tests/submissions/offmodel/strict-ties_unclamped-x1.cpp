// fetchColor compares with strict > everywhere, so a tie between x and y
// fails both tests and falls to the z faces, which the direction does not
// touch. readTexture does not clamp x1 = x0 + 1 (reads past the face on the
// last texel of the last row).
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    const double ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
    int face;
    double s, t, m;
    if (ax > ay && ax > az)      { m = ax; face = d.x > 0 ? FACE_POS_X : FACE_NEG_X; s = d.x > 0 ? d.z : -d.z; t = d.y; }
    else if (ay > ax && ay > az) { m = ay; face = d.y > 0 ? FACE_POS_Y : FACE_NEG_Y; s = d.x; t = d.y > 0 ? d.z : -d.z; }
    else                         { m = az; face = d.z > 0 ? FACE_POS_Z : FACE_NEG_Z; s = d.x; t = d.z > 0 ? -d.y : d.y; }
    if (m == 0) return Color();
    return readTexture(faceAddress(face), (1 + s / m) / 2, (1 + t / m) / 2);
}

// readTexture:begin
Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const double px = u * m_FaceWidth, py = v * m_FaceHeight;
    const int x0 = std::clamp((int)px, 0, m_FaceWidth - 1), y0 = std::clamp((int)py, 0, m_FaceHeight - 1);
    const int x1 = x0 + 1, y1 = std::min(y0 + 1, m_FaceHeight - 1);      // x1 not clamped
    const double a = px - (int)px, b = py - (int)py;
    auto at = [&](int x, int y) { const float* p = addr + 3 * (y * m_FaceWidth + x); return Color(p[0], p[1], p[2]); };
    return (1 - b) * ((1 - a) * at(x0, y0) + a * at(x1, y0)) + b * ((1 - a) * at(x0, y1) + a * at(x1, y1));
}
// readTexture:end
