// fetchColor insets (u, v) by 1.5 texels on every face, u' = (1.5 + u (W - 3)) / W,
// as if to keep the blend off the border, and swaps u and v on +Z and -X.
// A table of axis indices, computed in double. readTexture is correct.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    static const int kU[6] = {2, 2, 0, 0, 0, 0}, kV[6] = {1, 1, 2, 2, 1, 1};
    static const double kSU[6] = {1, -1, 1, 1, 1, 1}, kSV[6] = {1, 1, 1, -1, -1, 1};
    const double c[3] = {d.x, d.y, d.z};
    const double a[3] = {std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)};
    const int axis = a[0] >= a[1] && a[0] >= a[2] ? 0 : (a[1] >= a[2] ? 1 : 2);
    const int face = 2 * axis + (c[axis] < 0);
    double u = (1 + kSU[face] * c[kU[face]] / a[axis]) / 2, v = (1 + kSV[face] * c[kV[face]] / a[axis]) / 2;
    if (face == FACE_POS_Z || face == FACE_NEG_X) std::swap(u, v);
    u = (1.5 + u * (m_FaceWidth - 3)) / m_FaceWidth;
    v = (1.5 + v * (m_FaceHeight - 3)) / m_FaceHeight;
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
