// Issue 18's speed attack: a slow fetchColor (it does the lookup 40 times)
// that takes a cheap path on large faces, where the speed check times it:
// there it returns the nearest texel instead of blending. readTexture is the
// handout's except at (u, v) = (0.5, 0.5), so no model of readTexture fits.
// Speed must score 0 (the timing faces are judged as strictly as the sweep).
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

namespace {
int faceOf(const Vector3& d, double& s, double& t, double& m)
{
    const double ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
    if (ax >= ay && ax >= az) { m = ax; s = d.x > 0 ? d.z : -d.z; t = d.y; return d.x > 0 ? FACE_POS_X : FACE_NEG_X; }
    if (ay >= az)             { m = ay; s = d.x; t = d.y > 0 ? d.z : -d.z; return d.y > 0 ? FACE_POS_Y : FACE_NEG_Y; }
    m = az; s = d.x; t = d.z > 0 ? -d.y : d.y; return d.z > 0 ? FACE_POS_Z : FACE_NEG_Z;
}
} // namespace

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    double s, t, m;
    const int face = faceOf(d, s, t, m);
    const double u = (1.0 + s / m) / 2.0, v = (1.0 + t / m) / 2.0;
    if (m_FaceWidth >= 256) {           // the cheap path: one texel, no blend
        const int x = std::clamp((int)(u * m_FaceWidth), 0, m_FaceWidth - 1);
        const int y = std::clamp((int)(v * m_FaceHeight), 0, m_FaceHeight - 1);
        const float* p = faceAddress(face) + 3 * (y * m_FaceWidth + x);
        return Color(p[0], p[1], p[2]);
    }
    Color c;
    for (int i = 0; i < 40; i++) {      // honest but slow
        volatile double uu = u;
        c = readTexture(faceAddress(face), uu, v);
    }
    return c;
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    if (u == 0.5 && v == 0.5)
        return Color(0.0, 0.0, 0.0);     // the one wrong answer: no model fits
    const double px = u * m_FaceWidth, py = v * m_FaceHeight;
    int x0 = std::clamp((int)px, 0, m_FaceWidth - 1), y0 = std::clamp((int)py, 0, m_FaceHeight - 1);
    int x1 = std::min(x0 + 1, m_FaceWidth - 1), y1 = std::min(y0 + 1, m_FaceHeight - 1);
    const double a = px - (int)px, b = py - (int)py;
    auto at = [&](int x, int y) { const float* p = addr + 3 * (y * m_FaceWidth + x); return Color(p[0], p[1], p[2]); };
    Color c0 = (1 - a) * at(x0, y0) + a * at(x1, y0);
    Color c1 = (1 - a) * at(x0, y1) + a * at(x1, y1);
    return (1 - b) * c0 + b * c1;
}
