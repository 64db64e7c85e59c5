// A correct solution with helper functions of its own and standard headers;
// its extra global symbols (functions, a constant, a counter) must not
// disturb the build.
#include "EnvironmentMap.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

const double kHalf = 0.5;
long g_lookups = 0;  // a debugging counter a student might leave in

double lerp(double a, double b, double t)
{
    return a + (b - a) * t;
}

Color lerpColor(const Color& a, const Color& b, double t)
{
    return Color(lerp(a.r, b.r, t), lerp(a.g, b.g, t), lerp(a.b, b.b, t));
}

static double toUnit(double s, double m)
{
    return kHalf * (s / m + 1.0);
}

void debugPrint(const Vector3& d)
{
    std::printf("(%g, %g, %g)\n", d.x, d.y, d.z);
}

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    ++g_lookups;
    const std::array<double, 3> c = {direction.x, direction.y, direction.z};
    const std::array<double, 3> a = {std::abs(c[0]), std::abs(c[1]), std::abs(c[2])};
    const int major = (a[0] >= a[1] && a[0] >= a[2]) ? 0 : (a[1] >= a[2] ? 1 : 2);
    const double m = a[major];
    if (!(m > 0))
        return Color(0, 0, 0);   // zero or NaN: no face; any colour will do, crashing will not
    const bool positive = c[major] > 0;
    const int face = 2 * major + (positive ? 0 : 1);
    double u = 0, v = 0;
    if (major == 0) {
        u = toUnit(positive ? c[2] : -c[2], m);
        v = toUnit(c[1], m);
    } else if (major == 1) {
        u = toUnit(c[0], m);
        v = toUnit(positive ? c[2] : -c[2], m);
    } else {
        u = toUnit(c[0], m);
        v = toUnit(positive ? -c[1] : c[1], m);
    }
    return readTexture(faceAddress(face), u, v);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const double px = u * m_FaceWidth;
    const double py = v * m_FaceHeight;
    const double fx = std::floor(px), fy = std::floor(py);
    const int x0 = std::clamp(static_cast<int>(fx), 0, m_FaceWidth - 1);
    const int x1 = std::clamp(static_cast<int>(fx) + 1, 0, m_FaceWidth - 1);
    const int y0 = std::clamp(static_cast<int>(fy), 0, m_FaceHeight - 1);
    const int y1 = std::clamp(static_cast<int>(fy) + 1, 0, m_FaceHeight - 1);
    auto texel = [&](int x, int y) {
        const float* t = addr + 3 * (static_cast<std::size_t>(y) * m_FaceWidth + x);
        return Color(t[0], t[1], t[2]);
    };
    const Color c0 = lerpColor(texel(x0, y0), texel(x1, y0), px - fx);
    const Color c1 = lerpColor(texel(x0, y1), texel(x1, y1), px - fx);
    return lerpColor(c0, c1, py - fy);
}
