// TRUTH (written before any grading; checked against tests/helpers/assignment_model.py
// by tests/submissions/blind/check_truth.py):
//   WRONG, in readTexture only. fetchColor is right (one function template per face,
//   FaceLookup<Axis, Negative>, instantiated six times; ties x, y, z).
//   The mistake (an engine's "smooth it with a box filter" habit): readTexture takes the
//   starting code's nearest texel (xc, yc) = ((int)(uW), (int)(vH)), clamped, and returns
//   the plain average of the 3 x 3 texels around it (each clamped to the face): nine fixed
//   weights of 1/9, whatever (u, v) is inside the texel, over a 3-texel-wide window. It is
//   not the handout's 2 x 2 blend with weights from the fractional parts of p.
//   Expected: read_texture loses nearly all 25 points (wrong almost everywhere; right only
//   where the 3x3 mean happens to equal the blend, e.g. on a constant texture); fetch_sweep,
//   diagnosis keep full points; arrows probably keep (a blurred arrow still points the same
//   way); renders lose some (a blurrier environment); stability may lose a little (colours);
//   speed keeps or loses a little (9 reads). A readTexture id should say the weights do not
//   depend on p / more than four texels are read (e.g. constant-weights or not-a-blend).
//   What a student must change: read only the four texels around p = (uW, vH), floor(p) and
//   floor(p) + 1, clamped, and blend them with alpha, beta = the fractional parts of p.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

namespace {

template <int Axis, bool Negative>
struct FaceLookup;

// (s, t) of README.md's table for each face, from the components divided by m.
template <> struct FaceLookup<0, false> { static constexpr int face = FACE_POS_X; static double s(const double* c) { return c[2]; }  static double t(const double* c) { return c[1]; } };
template <> struct FaceLookup<0, true>  { static constexpr int face = FACE_NEG_X; static double s(const double* c) { return -c[2]; } static double t(const double* c) { return c[1]; } };
template <> struct FaceLookup<1, false> { static constexpr int face = FACE_POS_Y; static double s(const double* c) { return c[0]; }  static double t(const double* c) { return c[2]; } };
template <> struct FaceLookup<1, true>  { static constexpr int face = FACE_NEG_Y; static double s(const double* c) { return c[0]; }  static double t(const double* c) { return -c[2]; } };
template <> struct FaceLookup<2, false> { static constexpr int face = FACE_POS_Z; static double s(const double* c) { return c[0]; }  static double t(const double* c) { return -c[1]; } };
template <> struct FaceLookup<2, true>  { static constexpr int face = FACE_NEG_Z; static double s(const double* c) { return c[0]; }  static double t(const double* c) { return c[1]; } };

template <int Axis, bool Negative>
Color look(const EnvironmentMap& map, const double* c, double m)
{
    using F = FaceLookup<Axis, Negative>;
    const double n[3] = {c[0] / m, c[1] / m, c[2] / m};
    return map.readTexture(map.faceAddress(F::face), (1 + F::s(n)) / 2, (1 + F::t(n)) / 2);
}

template <int Axis>
Color lookAlong(const EnvironmentMap& map, const double* c, double m)
{
    return c[Axis] > 0 ? look<Axis, false>(map, c, m) : look<Axis, true>(map, c, m);
}

} // namespace

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    const double c[3] = {direction.x, direction.y, direction.z};
    const double a[3] = {std::fabs(c[0]), std::fabs(c[1]), std::fabs(c[2])};
    const double m = std::max(a[0], std::max(a[1], a[2]));
    if (!(m > 0) || !std::isfinite(m) || std::isnan(c[0] + c[1] + c[2]))
        return Color();
    if (a[0] == m) return lookAlong<0>(*this, c, m);
    if (a[1] == m) return lookAlong<1>(*this, c, m);
    return lookAlong<2>(*this, c, m);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const int xc = std::max(0, std::min((int)(u * m_FaceWidth), m_FaceWidth - 1));
    const int yc = std::max(0, std::min((int)(v * m_FaceHeight), m_FaceHeight - 1));
    // A 3x3 box filter around the nearest texel, to smooth out the blocks.
    Color sum;
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            const int x = std::max(0, std::min(xc + dx, m_FaceWidth - 1));
            const int y = std::max(0, std::min(yc + dy, m_FaceHeight - 1));
            const float* t = addr + 3 * (y * m_FaceWidth + x);
            sum += Color(t[0], t[1], t[2]);
        }
    return sum * (1.0 / 9.0);
}
