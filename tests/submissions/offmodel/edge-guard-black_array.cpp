// Issue 29, pattern 10 (its second shape). fetchColor is the table's, but
// before calling readTexture it returns black unless u < 1 and v < 1 (a
// guard against reading x = W, written in the wrong function): directions
// whose u or v is exactly 1 (the right and top edges of every face, and the
// cube's edges and corners there) come back black with no readTexture call.
// readTexture is the handout's, clamped: the guard was never needed.
// Truth (written before grading):
//   - fetch_sweep and stability lose points (edges, corners, face grids at
//     u = 1 or v = 1); read_texture keeps them.
//   - No false cause: not uv-inset, not uv-range, not "reads the texels
//     itself". The report shows a direction at u = 1 or v = 1 that makes no
//     readTexture call and returns black, where the table asks (u, v) with a 1.
#include "EnvironmentMap.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace {

// For each face: (s, t) = the signed components along u and v; the face's axis.
using Pick = std::array<double, 2> (*)(double, double, double);
const std::array<Pick, FACE_COUNT> kAlong = {
    [](double, double y, double z) { return std::array<double, 2>{z, y}; },
    [](double, double y, double z) { return std::array<double, 2>{-z, y}; },
    [](double x, double, double z) { return std::array<double, 2>{x, z}; },
    [](double x, double, double z) { return std::array<double, 2>{x, -z}; },
    [](double x, double y, double) { return std::array<double, 2>{x, -y}; },
    [](double x, double y, double) { return std::array<double, 2>{x, y}; },
};

} // namespace

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    const std::array<double, 3> a = {std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)};
    const int axis = a[0] >= a[1] && a[0] >= a[2] ? 0 : (a[1] >= a[2] ? 1 : 2);
    const double m = a[axis];
    if (!(m > 0) || !std::isfinite(m))
        return Color(0, 0, 0);
    const double c = axis == 0 ? d.x : (axis == 1 ? d.y : d.z);
    const int face = 2 * axis + (c > 0 ? 0 : 1);
    const std::array<double, 2> st = kAlong[face](d.x, d.y, d.z);
    const double u = (1 + st[0] / m) / 2, v = (1 + st[1] / m) / 2;
    if (!(u < 1 && v < 1))      // the mistake: the edge texels are readTexture's to clamp
        return Color(0, 0, 0);
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
