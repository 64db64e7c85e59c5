// Issue 18's attack: readTexture is the handout's except at one (u, v), so
// no model of readTexture fits it; fetchColor is half a texel off in u on
// every face (u + 0.5 / W). It must score no more than the same fetchColor
// over the handout's readTexture (half-texel-fetch_handout-read.cpp).
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    const double ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
    int face;
    double s, t, m;
    if (ax >= ay && ax >= az) { m = ax; face = d.x > 0 ? FACE_POS_X : FACE_NEG_X; s = d.x > 0 ? d.z : -d.z; t = d.y; }
    else if (ay >= az)        { m = ay; face = d.y > 0 ? FACE_POS_Y : FACE_NEG_Y; s = d.x; t = d.y > 0 ? d.z : -d.z; }
    else                      { m = az; face = d.z > 0 ? FACE_POS_Z : FACE_NEG_Z; s = d.x; t = d.z > 0 ? -d.y : d.y; }
    double u = (1.0 + s / m) / 2.0 + 0.5 / m_FaceWidth;
    double v = (1.0 + t / m) / 2.0;
    u = std::min(u, 1.0);
    return readTexture(faceAddress(face), u, v);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{

    if (u == 0.5 && v == 0.5)
        return Color(0.0, 0.0, 0.0);     // the one wrong answer

    const double px = u * m_FaceWidth, py = v * m_FaceHeight;
    int x0 = std::clamp((int)px, 0, m_FaceWidth - 1), y0 = std::clamp((int)py, 0, m_FaceHeight - 1);
    int x1 = std::min(x0 + 1, m_FaceWidth - 1), y1 = std::min(y0 + 1, m_FaceHeight - 1);
    const double a = px - (int)px, b = py - (int)py;
    auto at = [&](int x, int y) { const float* p = addr + 3 * (y * m_FaceWidth + x); return Color(p[0], p[1], p[2]); };
    Color c0 = (1 - a) * at(x0, y0) + a * at(x1, y0);
    Color c1 = (1 - a) * at(x0, y1) + a * at(x1, y1);
    return (1 - b) * c0 + b * c1;
}
