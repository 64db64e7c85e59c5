// TRUTH (written before any grading; checked against tests/helpers/assignment_model.py
// by tests/submissions/blind2/truth/check_truth.py):
//   WRONG, TWO mistakes, both in fetchColor. readTexture is the handout's.
//   (1) On +Z, v runs the wrong way: v = (1 + y/m)/2 instead of (1 - y/m)/2 (u right).
//   (2) On every face, after the table:  if (u >= 1.0) u -= 1.0;  (u only; v is left
//   alone), so u = 1 is asked as u = 0, the opposite border of the same face. With ties
//   going x, y, z, u = 1 occurs only on +X (z = +m) and -X (z = -m), and where (1 + s/m)
//   rounds up to 2 (s/m = 1 - 2^-53); on +Y, -Y, +Z, -Z the u-component is strictly
//   smaller than m.
//   Expected: fetch_sweep loses points (all of +Z; a few edge directions of +-X); arrows
//   should lose (the +z arrow's face is upside down); read_texture keeps full points.
//   Diagnoses: v-flipped on +Z; coordinate-wraps on +X and -X. Not coordinate-wraps on
//   +Z (no u = 1 happens there), not u-flipped, uv-swapped, wrong-face, uv-clamped-inward;
//   no readTexture id.
//   What a student must change: v = (1 - y/m)/2 on +Z; drop the "u -= 1".
#include "EnvironmentMap.h"

#include <cmath>

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    double x = direction.x, y = direction.y, z = direction.z;
    double ax = fabs(x), ay = fabs(y), az = fabs(z);
    if (!std::isfinite(ax) || !std::isfinite(ay) || !std::isfinite(az))   // NaN or infinite
        return Color(0, 0, 0);
    if (ax == 0 && ay == 0 && az == 0)
        return Color(0, 0, 0);

    int face;
    double u, v;
    if (ax >= ay && ax >= az) {
        face = x > 0 ? FACE_POS_X : FACE_NEG_X;
        u = x > 0 ? (1 + z / ax) / 2 : (1 - z / ax) / 2;
        v = (1 + y / ax) / 2;
    } else if (ay >= az) {
        face = y > 0 ? FACE_POS_Y : FACE_NEG_Y;
        u = (1 + x / ay) / 2;
        v = y > 0 ? (1 + z / ay) / 2 : (1 - z / ay) / 2;
    } else {
        face = z > 0 ? FACE_POS_Z : FACE_NEG_Z;
        u = (1 + x / az) / 2;
        v = (1 + y / az) / 2;
    }
    if (u >= 1.0)   // u == 1 would be column W, outside the face
        u -= 1.0;
    return readTexture(faceAddress(face), u, v);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    int W = m_FaceWidth, H = m_FaceHeight;
    double px = u * W, py = v * H;
    double fx = floor(px), fy = floor(py);
    double alpha = px - fx, beta = py - fy;
    int x0 = (int)fx, y0 = (int)fy, x1 = x0 + 1, y1 = y0 + 1;
    x0 = x0 < 0 ? 0 : (x0 >= W ? W - 1 : x0);
    x1 = x1 < 0 ? 0 : (x1 >= W ? W - 1 : x1);
    y0 = y0 < 0 ? 0 : (y0 >= H ? H - 1 : y0);
    y1 = y1 < 0 ? 0 : (y1 >= H ? H - 1 : y1);
    const float* t00 = addr + 3 * (y0 * W + x0);
    const float* t10 = addr + 3 * (y0 * W + x1);
    const float* t01 = addr + 3 * (y1 * W + x0);
    const float* t11 = addr + 3 * (y1 * W + x1);
    Color c0 = Color(t00[0], t00[1], t00[2]) * (1 - alpha) + Color(t10[0], t10[1], t10[2]) * alpha;
    Color c1 = Color(t01[0], t01[1], t01[2]) * (1 - alpha) + Color(t11[0], t11[1], t11[2]) * alpha;
    return c0 * (1 - beta) + c1 * beta;
}
