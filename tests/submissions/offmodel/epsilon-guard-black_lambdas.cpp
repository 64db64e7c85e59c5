// Issue 29, pattern 8. fetchColor, in double throughout (no float anywhere),
// returns black without calling readTexture when the largest |component| m
// is not above 1e-9 (a guard "against division by zero" that also catches
// every short direction). Right for every direction with m > 1e-9.
// readTexture is the handout's.
// Truth (written before grading):
//   - stability loses points (its tiny directions: 5e-324, 1e-310 come back
//     black); read_texture, arrows, renders keep every point. (Corrected
//     when the numbers were checked: fetch_sweep loses points too, its
//     lengths 1e-30 to 1e30 put a third of their directions below 1e-9.)
//   - Not float-precision (there is no float) and not length-overflow
//     (nothing is squared): the report must not say "the components go
//     through float". What is observed: for those directions fetchColor
//     made no readTexture call and returned black. What to fix leads to the
//     guard: only a zero (or NaN, infinite) direction may skip the lookup
//     (`length-dependent`, its two calls: one short, no readTexture call
//     and black; the same direction near length 1, the table's request;
//     and the sweep's `black-without-lookup`: every direction it skipped is
//     shorter than every one it looked up).
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    const double ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
    const double m = std::max({ax, ay, az});
    const double epsilon = 1e-9;
    if (!(m > epsilon) || !std::isfinite(m))    // the mistake: short directions are not zero
        return Color(0, 0, 0);
    const auto look = [&](int face, double s, double t) {
        return readTexture(faceAddress(face), (1 + s / m) / 2, (1 + t / m) / 2);
    };
    if (m == ax)
        return d.x > 0 ? look(FACE_POS_X, d.z, d.y) : look(FACE_NEG_X, -d.z, d.y);
    if (m == ay)
        return d.y > 0 ? look(FACE_POS_Y, d.x, d.z) : look(FACE_NEG_Y, d.x, -d.z);
    return d.z > 0 ? look(FACE_POS_Z, d.x, -d.y) : look(FACE_NEG_Z, d.x, d.y);
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
