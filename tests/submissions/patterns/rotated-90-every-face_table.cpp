// A face table (the handout's signs and components), but every face's
// (u, v) turned by 90 degrees, as if the faces were cut from a cross turned
// on its side: u = 1 - t and v = s, where (s, t) are the table's (u, v).
// On every face u and v are swapped and the new u runs the wrong way.
// readTexture is the handout's.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

namespace {
struct FaceRow { int face, s_axis; double s_sign; int t_axis; double t_sign; };
const FaceRow kRows[6] = {
    {FACE_POS_X, 2, +1, 1, +1}, {FACE_NEG_X, 2, -1, 1, +1},
    {FACE_POS_Y, 0, +1, 2, +1}, {FACE_NEG_Y, 0, +1, 2, -1},
    {FACE_POS_Z, 0, +1, 1, -1}, {FACE_NEG_Z, 0, +1, 1, +1},
};
}

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    const double c[3] = {d.x, d.y, d.z};
    int axis = 0;
    for (int i = 1; i < 3; ++i)
        if (std::fabs(c[i]) > std::fabs(c[axis])) axis = i;
    const FaceRow& r = kRows[2 * axis + (c[axis] < 0)];
    const double m = std::fabs(c[axis]);
    const double s = 0.5 * (1 + r.s_sign * c[r.s_axis] / m), t = 0.5 * (1 + r.t_sign * c[r.t_axis] / m);
    return readTexture(faceAddress(r.face), 1 - t, s);
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
