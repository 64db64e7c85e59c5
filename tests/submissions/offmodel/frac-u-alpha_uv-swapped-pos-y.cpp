// readTexture blends with alpha = frac(u) and beta = frac(v) (that is, u and
// v themselves) instead of the fractional parts of uW and vH. fetchColor
// (float (u, v), a switch) swaps u and v on +Y; elsewhere it is right.
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
    if (face == FACE_POS_Y) std::swap(u, v);
    return readTexture(faceAddress(face), u, v);
}

// readTexture:begin
Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const int x0 = std::clamp((int)(u * m_FaceWidth), 0, m_FaceWidth - 1);
    const int y0 = std::clamp((int)(v * m_FaceHeight), 0, m_FaceHeight - 1);
    const int x1 = std::min(x0 + 1, m_FaceWidth - 1), y1 = std::min(y0 + 1, m_FaceHeight - 1);
    const double a = u - std::floor(u), b = v - std::floor(v);     // the mistake: frac(u), not frac(uW)
    auto at = [&](int x, int y) { const float* p = addr + 3 * (y * m_FaceWidth + x); return Color(p[0], p[1], p[2]); };
    return (1 - b) * ((1 - a) * at(x0, y0) + a * at(x1, y0)) + b * ((1 - a) * at(x0, y1) + a * at(x1, y1));
}
// readTexture:end
