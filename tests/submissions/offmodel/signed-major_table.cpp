// A face table indexed by axis and sign, with m the *signed* major component
// (not its magnitude): on -X, -Y and -Z both s/m and t/m change sign, so u
// and v run the wrong way on those three faces. readTexture is correct.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

namespace {
// For each axis and sign: the face, and which components give s and t with their signs.
struct Row { int face; int s; double ss; int t; double ts; };
const Row kTable[3][2] = {
    {{FACE_POS_X, 2, +1, 1, +1}, {FACE_NEG_X, 2, -1, 1, +1}},
    {{FACE_POS_Y, 0, +1, 2, +1}, {FACE_NEG_Y, 0, +1, 2, -1}},
    {{FACE_POS_Z, 0, +1, 1, -1}, {FACE_NEG_Z, 0, +1, 1, +1}},
};
}

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    const double c[3] = {d.x, d.y, d.z};
    int axis = 0;
    for (int i = 1; i < 3; i++)
        if (std::fabs(c[i]) > std::fabs(c[axis])) axis = i;
    const Row& r = kTable[axis][c[axis] < 0];
    const double m = c[axis];                       // signed: the mistake
    const double u = 0.5 * (1.0 + r.ss * c[r.s] / m);
    const double v = 0.5 * (1.0 + r.ts * c[r.t] / m);
    return readTexture(faceAddress(r.face), u, v);
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
