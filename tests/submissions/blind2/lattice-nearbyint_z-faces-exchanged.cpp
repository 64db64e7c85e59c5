// TRUTH (written before any grading; checked against tests/helpers/assignment_model.py
// by tests/submissions/blind2/truth/check_truth.py):
//   WRONG, TWO mistakes, one in each function.
//   (1) fetchColor: the +Z and -Z faces are exchanged. The student numbers the front face
//   (-Z) 4 and the back face (+Z) 5 (kFront/kBack below), so a direction with z major and
//   z > 0 asks readTexture(faceAddress(5), u, v) with +Z's (u, v) = ((1 + x/m)/2, (1 - y/m)/2),
//   and z major, z < 0 asks faceAddress(4) with -Z's (u, v) = ((1 + x/m)/2, (1 + y/m)/2).
//   Every other face is right (if-chain, x before y before z at ties; zero, NaN, infinite
//   directions return black). Ties: a direction on an edge between a Z face and an X or Y
//   face goes to X or Y, so only directions with |z| strictly largest are wrong.
//   (2) readTexture: the lattice point is std::nearbyint(p) (round half to EVEN, the default
//   rounding mode) instead of floor(p); alpha = uW - x0, beta = vH - y0 from the rounded
//   point (in [-0.5, 0.5]); x1 = x0 + 1; all four clamped to the face afterwards.
//   Where frac(uW) < 0.5 it is the handout's; where frac(uW) > 0.5 (or = 0.5 with
//   floor(uW) odd) x0 is one too far right and alpha < 0 (extrapolation). Same on v.
//   Expected: fetch_sweep loses points on +Z and -Z; read_texture loses points; arrows
//   should lose (the blue +z arrow is read from the -Z face).
//   Diagnoses: wrong-face (or face-order) on +Z and -Z, and lattice-rounded. Not u-/v-flipped,
//   not uv-swapped/rotated (the (u, v) are each face's own), no other readTexture id.
//   What a student must change: +Z is face 4 and -Z face 5 (use FACE_POS_Z / FACE_NEG_Z);
//   x0 = floor(uW), y0 = floor(vH).
#include "EnvironmentMap.h"

#include <cmath>

namespace {
const int kFront = 4;   // -Z, the face the camera looks at
const int kBack = 5;    // +Z
}

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    const double x = direction.x, y = direction.y, z = direction.z;
    if (std::isnan(x) || std::isnan(y) || std::isnan(z) || std::isinf(x) || std::isinf(y) || std::isinf(z))
        return Color(0, 0, 0);
    const double ax = std::fabs(x), ay = std::fabs(y), az = std::fabs(z);
    int face;
    double u, v;
    if (ax >= ay && ax >= az) {
        if (ax == 0)
            return Color(0, 0, 0);
        if (x > 0) { face = FACE_POS_X; u = (1 + z / ax) / 2; v = (1 + y / ax) / 2; }
        else       { face = FACE_NEG_X; u = (1 - z / ax) / 2; v = (1 + y / ax) / 2; }
    } else if (ay >= az) {
        if (y > 0) { face = FACE_POS_Y; u = (1 + x / ay) / 2; v = (1 + z / ay) / 2; }
        else       { face = FACE_NEG_Y; u = (1 + x / ay) / 2; v = (1 - z / ay) / 2; }
    } else {
        if (z > 0) { face = kBack;  u = (1 + x / az) / 2; v = (1 - y / az) / 2; }
        else       { face = kFront; u = (1 + x / az) / 2; v = (1 + y / az) / 2; }
    }
    return readTexture(faceAddress(face), u, v);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const double px = u * m_FaceWidth;
    const double py = v * m_FaceHeight;
    int x0 = (int)std::nearbyint(px);
    int y0 = (int)std::nearbyint(py);
    const double alpha = px - x0;
    const double beta = py - y0;
    int x1 = x0 + 1, y1 = y0 + 1;
    if (x0 > m_FaceWidth - 1) x0 = m_FaceWidth - 1;
    if (x1 > m_FaceWidth - 1) x1 = m_FaceWidth - 1;
    if (y0 > m_FaceHeight - 1) y0 = m_FaceHeight - 1;
    if (y1 > m_FaceHeight - 1) y1 = m_FaceHeight - 1;
    if (x0 < 0) x0 = 0;
    if (y0 < 0) y0 = 0;
    if (x1 < 0) x1 = 0;
    if (y1 < 0) y1 = 0;
    const float* c00 = addr + 3 * (y0 * m_FaceWidth + x0);
    const float* c10 = addr + 3 * (y0 * m_FaceWidth + x1);
    const float* c01 = addr + 3 * (y1 * m_FaceWidth + x0);
    const float* c11 = addr + 3 * (y1 * m_FaceWidth + x1);
    double out[3];
    for (int k = 0; k < 3; ++k) {
        const double c0 = (1 - alpha) * c00[k] + alpha * c10[k];
        const double c1 = (1 - alpha) * c01[k] + alpha * c11[k];
        out[k] = (1 - beta) * c0 + beta * c1;
    }
    return Color(out[0], out[1], out[2]);
}
