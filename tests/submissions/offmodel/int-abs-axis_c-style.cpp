/* Issue 29, pattern 11. Written the C way: the axis is chosen by int
 * magnitudes, int a = abs(c) (in C, abs(int) on the double truncated; here
 * the double's magnitude stored in an int: the same whole part). A unit
 * direction has every whole part 0, so the first branch (x) wins and
 * every direction shorter than 1 goes to +X or -X; at lengths where the
 * whole parts differ (a component of 1e3) the choice is mostly right, and
 * it is wrong again where they tie. u and v are then computed on that face
 * with m = fabs of its component (outside [0, 1] off +/-X directions).
 * readTexture is the handout's.
 * Truth (written before grading):
 *   - fetch_sweep, stability, arrows, renders lose points; read_texture keeps them.
 *   - Per face: the +Y, -Y, +Z, -Z directions (at length 1) read from +X or
 *     -X: wrong-face on +Y, -Y, +Z, -Z; +X and -X right.
 *   - The report shows a direction whose face changes with its length (the
 *     same direction at length 1 and 1000 going to different faces), so
 *     What to fix leads to comparing |components| as doubles (fabs).
 *   - Not float-precision, not length-overflow, not not-divided-by-m.
 *   After the first grading: not-divided-by-m was named, and its title
 *   holds (the m divided by is the chosen axis's, not the largest
 *   |component|, wherever the axis is wrong): allowed beside the causes.
 *   uv-mismatch on +Y, -Y, +Z, -Z ("your code reads the right face") is
 *   false: those directions read +X or -X. */
#include "EnvironmentMap.h"

#include <stdlib.h>
#include <math.h>
#include <algorithm>

static int axis_of(const double c[3])
{
    int ax = abs(c[0]), ay = abs(c[1]), az = abs(c[2]);   /* the mistake: int magnitudes */
    if (ax >= ay && ax >= az)
        return 0;
    if (ay >= az)
        return 1;
    return 2;
}

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    const double c[3] = {d.x, d.y, d.z};
    const int axis = axis_of(c);
    const double m = fabs(c[axis]);
    const int face = 2 * axis + (c[axis] > 0 ? 0 : 1);
    double s, t;
    switch (face) {
    case FACE_POS_X: s = d.z;  t = d.y;  break;
    case FACE_NEG_X: s = -d.z; t = d.y;  break;
    case FACE_POS_Y: s = d.x;  t = d.z;  break;
    case FACE_NEG_Y: s = d.x;  t = -d.z; break;
    case FACE_POS_Z: s = d.x;  t = -d.y; break;
    default:         s = d.x;  t = d.y;  break;
    }
    return readTexture(faceAddress(face), (1 + s / m) / 2, (1 + t / m) / 2);
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
