// An attack on the live judge: fetchColor is half a texel off in u on every
// face, and readTexture, when called on its own (not from fetchColor) on the
// faces the fetchColor checks use (32, 16 or 256 texels wide), shifts u by
// the same half texel, so fetchColor's answers look like "the student's own
// readTexture at the handout's (u, v)". Elsewhere readTexture is the
// handout's except at (u, v) = (0.5, 0.5), so no model of it fits.
// It must score no more than half-texel-fetch_handout-read.cpp.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

namespace {
bool inFetch = false;
}

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    const double ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
    int face;
    double s, t, m;
    if (ax >= ay && ax >= az) { m = ax; face = d.x > 0 ? FACE_POS_X : FACE_NEG_X; s = d.x > 0 ? d.z : -d.z; t = d.y; }
    else if (ay >= az)        { m = ay; face = d.y > 0 ? FACE_POS_Y : FACE_NEG_Y; s = d.x; t = d.y > 0 ? d.z : -d.z; }
    else                      { m = az; face = d.z > 0 ? FACE_POS_Z : FACE_NEG_Z; s = d.x; t = d.z > 0 ? -d.y : d.y; }
    const double u = std::min((1.0 + s / m) / 2.0 + 0.5 / m_FaceWidth, 1.0);
    const double v = (1.0 + t / m) / 2.0;
    inFetch = true;
    const Color c = readTexture(faceAddress(face), u, v);
    inFetch = false;
    return c;
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    if (u == 0.5 && v == 0.5)
        return Color(0.0, 0.0, 0.0);
    if (!inFetch && (m_FaceWidth == 32 || m_FaceWidth == 16 || m_FaceWidth == 256) && m_FaceHeight == m_FaceWidth)
        u = std::min(u + 0.5 / m_FaceWidth, 1.0);       // consistent with fetchColor's shift
    const double px = u * m_FaceWidth, py = v * m_FaceHeight;
    int x0 = std::clamp((int)px, 0, m_FaceWidth - 1), y0 = std::clamp((int)py, 0, m_FaceHeight - 1);
    int x1 = std::min(x0 + 1, m_FaceWidth - 1), y1 = std::min(y0 + 1, m_FaceHeight - 1);
    const double a = px - (int)px, b = py - (int)py;
    auto at = [&](int x, int y) { const float* p = addr + 3 * (y * m_FaceWidth + x); return Color(p[0], p[1], p[2]); };
    return (1 - b) * ((1 - a) * at(x0, y0) + a * at(x1, y0)) + b * ((1 - a) * at(x0, y1) + a * at(x1, y1));
}
