// TRUTH (written before any grading; checked against tests/helpers/assignment_model.py
// by tests/submissions/blind2/truth/check_truth.py):
//   WRONG, in readTexture only, on the LAST COLUMN only. fetchColor is right (early returns
//   per face, x before y before z at ties; zero, NaN and infinite directions return black).
//   readTexture: x0 = floor(uW), y0 = floor(vH), both clamped to the face; then
//       if (x0 + 1 >= W) return texel(x0, y0);      // "no texel to the right"
//   and otherwise the handout's blend with x1 = x0 + 1 and y1 = min(y0 + 1, H - 1).
//   So on the last column (uW >= W - 1, which includes u = 1) it returns texel (W - 1, y0)
//   alone, no longer blending rows y0 and y0 + 1 by beta; the last ROW is handled as the
//   handout does (y1 clamped, blend along x kept). Wrong where uW >= W - 1 and
//   frac(vH) > 0 and y0 < H - 1; right everywhere else.
//   Expected: read_texture loses a few points (a strip one texel wide); fetch_sweep, arrows
//   keep full points; renders and stability may lose a little; speed keeps.
//   What it should be called: edge-single-texel (its own definition: on the last column
//   returns texel (x0, y0) alone instead of still blending along the other axis), said
//   for the last COLUMN; a sentence saying the last ROW stops blending would be false.
//   No fetchColor id, no other readTexture id (not unclamped-edge, wrapped-edge,
//   nearest-neighbor).
//   What a student must change: drop the early return; x1 = min(x0 + 1, W - 1).
#include "EnvironmentMap.h"

#include <cmath>

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    if (!std::isfinite(d.x) || !std::isfinite(d.y) || !std::isfinite(d.z))
        return Color(0, 0, 0);
    const double ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
    if (ax >= ay && ax >= az && ax > 0) {
        if (d.x > 0)
            return readTexture(faceAddress(FACE_POS_X), 0.5 * (1 + d.z / ax), 0.5 * (1 + d.y / ax));
        return readTexture(faceAddress(FACE_NEG_X), 0.5 * (1 - d.z / ax), 0.5 * (1 + d.y / ax));
    }
    if (ay >= az && ay > 0) {
        if (d.y > 0)
            return readTexture(faceAddress(FACE_POS_Y), 0.5 * (1 + d.x / ay), 0.5 * (1 + d.z / ay));
        return readTexture(faceAddress(FACE_NEG_Y), 0.5 * (1 + d.x / ay), 0.5 * (1 - d.z / ay));
    }
    if (az > 0) {
        if (d.z > 0)
            return readTexture(faceAddress(FACE_POS_Z), 0.5 * (1 + d.x / az), 0.5 * (1 - d.y / az));
        return readTexture(faceAddress(FACE_NEG_Z), 0.5 * (1 + d.x / az), 0.5 * (1 + d.y / az));
    }
    return Color(0, 0, 0);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const int W = m_FaceWidth, H = m_FaceHeight;
    const double px = u * W, py = v * H;
    int x0 = (int)std::floor(px);
    int y0 = (int)std::floor(py);
    if (x0 < 0) x0 = 0;
    if (x0 > W - 1) x0 = W - 1;
    if (y0 < 0) y0 = 0;
    if (y0 > H - 1) y0 = H - 1;
    const float* c00 = addr + 3 * (y0 * W + x0);
    if (x0 + 1 >= W)   // no texel to the right
        return Color(c00[0], c00[1], c00[2]);
    const int x1 = x0 + 1;
    const int y1 = (y0 + 1 < H) ? y0 + 1 : H - 1;
    const double alpha = px - std::floor(px);
    const double beta = py - std::floor(py);
    const float* c10 = addr + 3 * (y0 * W + x1);
    const float* c01 = addr + 3 * (y1 * W + x0);
    const float* c11 = addr + 3 * (y1 * W + x1);
    Color c0((1 - alpha) * c00[0] + alpha * c10[0], (1 - alpha) * c00[1] + alpha * c10[1], (1 - alpha) * c00[2] + alpha * c10[2]);
    Color c1((1 - alpha) * c01[0] + alpha * c11[0], (1 - alpha) * c01[1] + alpha * c11[1], (1 - alpha) * c01[2] + alpha * c11[2]);
    return Color((1 - beta) * c0.r + beta * c1.r, (1 - beta) * c0.g + beta * c1.g, (1 - beta) * c0.b + beta * c1.b);
}
