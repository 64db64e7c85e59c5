// Issue 29, pattern 6. fetchColor divides by the signed major component
// (the signs of ASSIGNMENT.md's table come out of it) and writes each
// coordinate as 0.5 * s / c + 0.5: the product 0.5 * s is computed before
// the division. For components of the smallest denormals, 0.5 * s rounds
// (0.5 * 5e-324 is 0): the direction (5e-324, 5e-324, 5e-324) asks +X for
// (0.5, 0.5) where the table gives (1, 1). Right at every other length
// (a normal s loses nothing: 0.5 * s is exact). readTexture is the handout's.
// Truth (written before grading):
//   - stability loses points on the tiny directions (only those whose
//     components are a few denormal steps); fetch_sweep, read_texture,
//     arrows, renders keep every point.
//   - No cause is proved by that observation alone: nothing false named (no
//     float-precision: no float; no length-overflow: nothing is squared;
//     no not-divided-by-m). The report shows the case in numbers: the
//     direction, the (u, v) asked and the table's.
//   After the first grading (nothing under "What to fix", the case only in
//   the details): the grader now asks each direction at lengths that differ
//   by powers of two and names `length-dependent` with the two calls (the
//   denormal one asks (0.5, 0.5), the same direction at 0.5 asks (1, 1)),
//   which leads to dividing first.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    const double x = direction.x, y = direction.y, z = direction.z;
    const double ax = std::fabs(x), ay = std::fabs(y), az = std::fabs(z);
    if (!(std::max({ax, ay, az}) > 0) || !std::isfinite(std::max({ax, ay, az})))
        return Color(0, 0, 0);
    int face;
    double u, v;
    if (ax >= ay && ax >= az) {
        face = x > 0 ? FACE_POS_X : FACE_NEG_X;
        u = 0.5 * z / x + 0.5;        // +X: (1 + z/m)/2, -X: (1 - z/m)/2
        v = 0.5 * y / ax + 0.5;
    } else if (ay >= az) {
        face = y > 0 ? FACE_POS_Y : FACE_NEG_Y;
        u = 0.5 * x / ay + 0.5;
        v = 0.5 * z / y + 0.5;        // +Y: (1 + z/m)/2, -Y: (1 - z/m)/2
    } else {
        face = z > 0 ? FACE_POS_Z : FACE_NEG_Z;
        u = 0.5 * x / az + 0.5;
        v = 0.5 - 0.5 * y / z;        // +Z: (1 - y/m)/2, -Z: (1 + y/m)/2
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
