// TRUTH (written before any grading; checked against tests/helpers/assignment_model.py
// by tests/submissions/blind/check_truth.py):
//   WRONG, TWO mistakes that nearly cancel.
//   1. fetchColor (a table of pointers to Vector3's members, one row per face) computes v
//      as 1 - (the table's v) on EVERY face ("images are stored top row first"): v runs
//      the wrong way on all six faces. u and the face are right; ties x, y, z.
//   2. readTexture counts rows from the top of the face: texel (x, y) is read at row
//      H - 1 - y (addr[3 * ((H - 1 - y) * W + x)]); otherwise the handout's clamped blend.
//   Together: for the table's v, the code reads at p_y' = (1 - v) H with rows reversed,
//   which is the handout's blend between rows floor(vH) - 1 and floor(vH) at position
//   vH - 1: the picture is right but ONE TEXEL LOWER (sampled one texel below where it
//   should be; exact except at the face's bottom and top rows and where vH is a whole
//   number, where the clamp/floor make it differ by other amounts). So the renders and the
//   arrows look almost right while each function alone is wrong.
//   Expected: fetch_sweep loses nearly all its 30 points (v flipped on all six faces; only
//   directions with v = 1/2 are right); diagnosis says v runs the wrong way on every face
//   (v-flipped on all six faces, not a face-order or rotation); read_texture loses most of
//   its 25 points, with rows read top-down named (rows-flipped or texture-v-flipped);
//   arrows keep; renders keep nearly all (one texel); stability keeps or loses a little;
//   speed keeps. "What to fix" must ask for BOTH fixes (fixing one alone turns every face
//   upside down end to end), not present one as the whole story.
//   What a student must change: in fetchColor use the table's v (drop the 1 - v); in
//   readTexture read texel (x, y) at addr[3 * (y * W + x)] (row 0 is the bottom row).
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

namespace {
struct FaceRow {
    int face;
    double Vector3::*major;
    double majorSign;
    double Vector3::*sAxis;
    double sSign;
    double Vector3::*tAxis;
    double tSign;
};

const FaceRow kRows[6] = {
    {FACE_POS_X, &Vector3::x, +1, &Vector3::z, +1, &Vector3::y, +1},
    {FACE_NEG_X, &Vector3::x, -1, &Vector3::z, -1, &Vector3::y, +1},
    {FACE_POS_Y, &Vector3::y, +1, &Vector3::x, +1, &Vector3::z, +1},
    {FACE_NEG_Y, &Vector3::y, -1, &Vector3::x, +1, &Vector3::z, -1},
    {FACE_POS_Z, &Vector3::z, +1, &Vector3::x, +1, &Vector3::y, -1},
    {FACE_NEG_Z, &Vector3::z, -1, &Vector3::x, +1, &Vector3::y, +1},
};
}

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    const double ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
    if (!std::isfinite(ax) || !std::isfinite(ay) || !std::isfinite(az))
        return Color();
    const int axis = (ax >= ay && ax >= az) ? 0 : (ay >= az ? 1 : 2);
    const int row = 2 * axis + ((d.*kRows[2 * axis].major) < 0 ? 1 : 0);
    const FaceRow& f = kRows[row];
    const double m = f.majorSign * (d.*f.major);
    if (!(m > 0))
        return Color();
    const double u = (1 + f.sSign * (d.*f.sAxis) / m) / 2;
    const double v = 1 - (1 + f.tSign * (d.*f.tAxis) / m) / 2;   // images are stored top row first
    return readTexture(faceAddress(f.face), u, v);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const int W = m_FaceWidth, H = m_FaceHeight;
    const double px = u * W, py = v * H;
    const int x0 = std::clamp((int)px, 0, W - 1), y0 = std::clamp((int)py, 0, H - 1);
    const int x1 = std::min(x0 + 1, W - 1), y1 = std::min(y0 + 1, H - 1);
    const double alpha = px - (int)px, beta = py - (int)py;
    // row 0 of the image is the top row
    auto texel = [&](int x, int y) { const float* p = addr + 3 * ((H - 1 - y) * W + x); return Color(p[0], p[1], p[2]); };
    const Color c0 = (1 - alpha) * texel(x0, y0) + alpha * texel(x1, y0);
    const Color c1 = (1 - alpha) * texel(x0, y1) + alpha * texel(x1, y1);
    return (1 - beta) * c0 + beta * c1;
}
