// Two fetchColor mistakes: an array of lambdas, one per face, gives the
// table's (s, t), then every face is turned by 90 degrees (u = 1 - t, v = s)
// and (u, v) are inset by one texel, u' = (1 + u (W - 2)) / W, to keep the
// blend off the border. readTexture is the handout's.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    struct ST { double s, t; };
    static ST (*const kTable[6])(double, double, double) = {
        [](double x, double y, double z) { return ST{z / x, y / x}; },     // +X, m = x
        [](double x, double y, double z) { return ST{z / x, -y / x}; },    // -X, m = -x
        [](double x, double y, double z) { return ST{x / y, z / y}; },     // +Y
        [](double x, double y, double z) { return ST{-x / y, z / y}; },    // -Y
        [](double x, double y, double z) { return ST{x / z, -y / z}; },    // +Z
        [](double x, double y, double z) { return ST{-x / z, -y / z}; },   // -Z
    };
    const double a[3] = {std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)};
    const int axis = (a[0] >= a[1] && a[0] >= a[2]) ? 0 : (a[1] >= a[2] ? 1 : 2);
    const double c = axis == 0 ? d.x : (axis == 1 ? d.y : d.z);
    const int face = 2 * axis + (c < 0);
    const ST st = kTable[face](d.x, d.y, d.z);
    const double s = (1 + st.s) / 2, t = (1 + st.t) / 2;
    const double u = 1 - t, v = s;                                          // turned 90 degrees
    return readTexture(faceAddress(face), (1 + u * (m_FaceWidth - 2)) / m_FaceWidth,
                       (1 + v * (m_FaceHeight - 2)) / m_FaceHeight);
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
