// TRUTH (written before any grading; checked against tests/helpers/assignment_model.py
// by tests/submissions/blind2/truth/check_truth.py):
//   RIGHT. 100/100 expected; no check should lose a point; no diagnosis id.
//   Style: fetchColor finds the major axis with a loop over the components (strict >, so
//   x before y before z at ties), face = 2 * axis + (component < 0), and reads u and v
//   from a table of {u axis, u sign, v axis, v sign} per face (the README's table as
//   data). Any non-finite component or a zero direction returns black.
//   readTexture splits p with std::modf (integer part and fraction in one call), clamps
//   the four lattice coordinates, and blends with the four bilinear weights
//   (1-a)(1-b), a(1-b), (1-a)b, ab summed in one expression per channel (the handout's
//   equations (1)-(3) expanded: equal up to rounding, about 1e-16 relative).
//   What a student must change: nothing.
#include "EnvironmentMap.h"

#include <cmath>

namespace {

struct FaceAxes {
    int uAxis;
    double uSign;
    int vAxis;
    double vSign;
};

// Indexed by face number (+X, -X, +Y, -Y, +Z, -Z); axes 0, 1, 2 are x, y, z.
constexpr FaceAxes kAxes[6] = {
    {2, +1.0, 1, +1.0},   // +X: u = ( z), v = ( y)
    {2, -1.0, 1, +1.0},   // -X: u = (-z), v = ( y)
    {0, +1.0, 2, +1.0},   // +Y: u = ( x), v = ( z)
    {0, +1.0, 2, -1.0},   // -Y: u = ( x), v = (-z)
    {0, +1.0, 1, -1.0},   // +Z: u = ( x), v = (-y)
    {0, +1.0, 1, +1.0},   // -Z: u = ( x), v = ( y)
};

inline int clampi(int q, int lo, int hi) { return q < lo ? lo : (q > hi ? hi : q); }

}  // namespace

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    const double c[3] = {direction.x, direction.y, direction.z};
    int major = 0;
    for (int i = 0; i < 3; ++i) {
        if (!std::isfinite(c[i]))
            return Color(0.0, 0.0, 0.0);
        if (std::fabs(c[i]) > std::fabs(c[major]))
            major = i;
    }
    const double m = std::fabs(c[major]);
    if (!(m > 0.0))
        return Color(0.0, 0.0, 0.0);
    const int face = 2 * major + (c[major] < 0.0 ? 1 : 0);
    const FaceAxes& a = kAxes[face];
    const double u = (1.0 + a.uSign * (c[a.uAxis] / m)) / 2.0;
    const double v = (1.0 + a.vSign * (c[a.vAxis] / m)) / 2.0;
    return readTexture(faceAddress(face), u, v);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    double ix, iy;
    const double a = std::modf(u * m_FaceWidth, &ix);    // alpha, and floor(p.x) in ix (p >= 0)
    const double b = std::modf(v * m_FaceHeight, &iy);   // beta
    const int x0 = clampi((int)ix, 0, m_FaceWidth - 1), x1 = clampi((int)ix + 1, 0, m_FaceWidth - 1);
    const int y0 = clampi((int)iy, 0, m_FaceHeight - 1), y1 = clampi((int)iy + 1, 0, m_FaceHeight - 1);
    const float* t00 = addr + 3 * (y0 * m_FaceWidth + x0);
    const float* t10 = addr + 3 * (y0 * m_FaceWidth + x1);
    const float* t01 = addr + 3 * (y1 * m_FaceWidth + x0);
    const float* t11 = addr + 3 * (y1 * m_FaceWidth + x1);
    const double w00 = (1 - a) * (1 - b), w10 = a * (1 - b), w01 = (1 - a) * b, w11 = a * b;
    double rgb[3];
    for (int k = 0; k < 3; ++k)
        rgb[k] = w00 * t00[k] + w10 * t10[k] + w01 * t01[k] + w11 * t11[k];
    return Color(rgb[0], rgb[1], rgb[2]);
}
