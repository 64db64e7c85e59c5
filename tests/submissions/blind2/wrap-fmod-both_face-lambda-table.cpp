// TRUTH (written before any grading; checked against tests/helpers/assignment_model.py
// by tests/submissions/blind2/truth/check_truth.py):
//   WRONG, in fetchColor only. Faces and the (u, v) table are right (a table of six
//   lambdas giving (s, t) per face, face = 2 * axis + (component < 0), x before y before z at
//   ties; zero, NaN and infinite directions return black), but then
//       u = std::fmod(u, 1.0); v = std::fmod(v, 1.0);   // "keep u, v in [0, 1)"
//   so a coordinate of exactly 1 is asked as 0: u = 1 or v = 1 jumps to the opposite
//   border of the same face. Every other coordinate is passed unchanged. u or v is exactly
//   1 on the edge directions where the face's u- or v-component equals +m with the table's
//   sign (ties go x, y, z: +X/-X can have u = 1 or v = 1, +Y/-Y only v = 1, +Z/-Z neither,
//   as their u, v components are strictly smaller than m), and also where (1 + s/m) rounds
//   up to 2 for s/m = 1 - 2^-53.
//   readTexture is the handout's (floor, clamp, equations (1)-(3)).
//   Expected: fetch_sweep loses points (edge directions); read_texture keeps full points;
//   arrows keep. Diagnosis: coordinate-wraps (on the faces where u or v = 1 occurs:
//   +X, -X, +Y, -Y); not uv-clamped-inward, uv-inset, uv-offset, u-/v-flipped, wrong-face,
//   tie-untouched-face, no readTexture id.
//   What a student must change: drop the fmod (u, v are already in [0, 1]; 1 is allowed).
#include "EnvironmentMap.h"

#include <cmath>

namespace {
using ST = void (*)(double, double, double, double&, double&);
// (s, t) for each face, the direction already divided by m; u = (1 + s) / 2, v = (1 + t) / 2.
const ST kST[6] = {
    [](double, double y, double z, double& s, double& t) { s = z; t = y; },    // +X
    [](double, double y, double z, double& s, double& t) { s = -z; t = y; },   // -X
    [](double x, double, double z, double& s, double& t) { s = x; t = z; },    // +Y
    [](double x, double, double z, double& s, double& t) { s = x; t = -z; },   // -Y
    [](double x, double y, double, double& s, double& t) { s = x; t = -y; },   // +Z
    [](double x, double y, double, double& s, double& t) { s = x; t = y; },    // -Z
};
}  // namespace

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    const double c[3] = {direction.x, direction.y, direction.z};
    for (double q : c)
        if (!std::isfinite(q))
            return Color(0, 0, 0);
    int axis = 0;
    if (std::fabs(c[1]) > std::fabs(c[axis])) axis = 1;
    if (std::fabs(c[2]) > std::fabs(c[axis])) axis = 2;
    const double m = std::fabs(c[axis]);
    if (m == 0)
        return Color(0, 0, 0);
    const int face = 2 * axis + (c[axis] < 0 ? 1 : 0);
    double s, t;
    kST[face](c[0] / m, c[1] / m, c[2] / m, s, t);
    double u = (1 + s) / 2, v = (1 + t) / 2;
    u = std::fmod(u, 1.0);   // keep u, v in [0, 1)
    v = std::fmod(v, 1.0);
    return readTexture(faceAddress(face), u, v);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const double px = u * m_FaceWidth, py = v * m_FaceHeight;
    const int ix = (int)std::floor(px), iy = (int)std::floor(py);
    const double alpha = px - ix, beta = py - iy;
    auto cx = [&](int x) { return x < 0 ? 0 : (x > m_FaceWidth - 1 ? m_FaceWidth - 1 : x); };
    auto cy = [&](int y) { return y < 0 ? 0 : (y > m_FaceHeight - 1 ? m_FaceHeight - 1 : y); };
    const int x0 = cx(ix), x1 = cx(ix + 1), y0 = cy(iy), y1 = cy(iy + 1);
    const float* c00 = addr + 3 * (y0 * m_FaceWidth + x0);
    const float* c10 = addr + 3 * (y0 * m_FaceWidth + x1);
    const float* c01 = addr + 3 * (y1 * m_FaceWidth + x0);
    const float* c11 = addr + 3 * (y1 * m_FaceWidth + x1);
    double out[3];
    for (int k = 0; k < 3; ++k)
        out[k] = (1 - beta) * ((1 - alpha) * c00[k] + alpha * c10[k]) + beta * ((1 - alpha) * c01[k] + alpha * c11[k]);
    return Color(out[0], out[1], out[2]);
}
