// Two fetchColor mistakes. Every component is divided by the signed major
// component in double (on -X, -Y and -Z that flips both u and v), then
// (u, v) are computed in float from the ratios, which lie in [-1, 1]. And
// on +Y the sign in front of x is wrong, so u runs the wrong way there too.
// readTexture is the handout's.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    const double ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
    const int axis = ax >= ay && ax >= az ? 0 : (ay >= az ? 1 : 2);
    const double major = axis == 0 ? d.x : (axis == 1 ? d.y : d.z);    // signed: the mistake
    const float x = (float)(d.x / major), y = (float)(d.y / major), z = (float)(d.z / major);
    const bool pos = major > 0;
    float u, v;
    int face;
    if (axis == 0)      { face = pos ? FACE_POS_X : FACE_NEG_X; u = 0.5f * (1 + (pos ? z : -z)); v = 0.5f * (1 + y); }
    else if (axis == 1) { face = pos ? FACE_POS_Y : FACE_NEG_Y; u = 0.5f * (1 + (pos ? -x : x)); v = 0.5f * (1 + (pos ? z : -z)); }
    else                { face = pos ? FACE_POS_Z : FACE_NEG_Z; u = 0.5f * (1 + x); v = 0.5f * (1 + (pos ? -y : y)); }
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
