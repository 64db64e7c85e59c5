// TRUTH (written before any grading; checked against tests/helpers/assignment_model.py
// by tests/submissions/blind/check_truth.py):
//   WRONG, in readTexture only. fetchColor is right (a switch on the major axis, the sign
//   chosen inside each case; ties x, y, z).
//   The mistake (GL_REPEAT on both axes, without the half-texel shift): readTexture takes
//   x0 = floor(uW) mod W and x1 = (x0 + 1) mod W, and the same on y with H, instead of
//   clamping. The blend weights are the handout's. So:
//   - inside the face (x0 <= W - 2 and y0 <= H - 2) it is the handout's bilinear;
//   - in the last column it blends texel W - 1 with texel 0 OF THE SAME ROW (the opposite
//     border of the face) instead of reading texel W - 1 alone; same in the last row (row 0);
//   - at u = 1 exactly, floor(W) mod W = 0: it reads column 0, the opposite border; same at
//     v = 1. On the cube those are the edges: every edge and corner direction that lands on
//     u = 1 or v = 1 of the face it picks gets a colour from the other side of that face.
//   Expected: read_texture loses part of its 25 points (right inside, wrong in the last
//   row/column and at 1); fetch_sweep and diagnosis keep full points (fetchColor asks for
//   the right face and (u, v)); stability may lose at edges/corners (seams); renders lose a
//   little (thin lines along some cube edges); arrows keep; speed keeps. Expected id: the
//   edges wrap (wrapped-edge) and nothing about fetchColor.
//   What a student must change: clamp the lattice points to [0, W-1] x [0, H-1]
//   (x1 = min(x0 + 1, W - 1), x0 = min(floor(uW), W - 1)) instead of taking them mod W.
#include "EnvironmentMap.h"

#include <cmath>

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    const double ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
    if (!std::isfinite(ax) || !std::isfinite(ay) || !std::isfinite(az))
        return Color();
    const int axis = ax >= ay && ax >= az ? 0 : (ay >= az ? 1 : 2);
    double m, s, t;
    int face;
    switch (axis) {
    case 0:
        m = ax;
        face = d.x > 0 ? FACE_POS_X : FACE_NEG_X;
        s = d.x > 0 ? d.z : -d.z;
        t = d.y;
        break;
    case 1:
        m = ay;
        face = d.y > 0 ? FACE_POS_Y : FACE_NEG_Y;
        s = d.x;
        t = d.y > 0 ? d.z : -d.z;
        break;
    default:
        m = az;
        face = d.z > 0 ? FACE_POS_Z : FACE_NEG_Z;
        s = d.x;
        t = d.z > 0 ? -d.y : d.y;
        break;
    }
    if (!(m > 0))
        return Color();
    return readTexture(faceAddress(face), 0.5 * (1 + s / m), 0.5 * (1 + t / m));
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const int W = m_FaceWidth, H = m_FaceHeight;
    const double px = u * W, py = v * H;
    const double fx = std::floor(px), fy = std::floor(py);
    const double alpha = px - fx, beta = py - fy;
    // repeat addressing, as the GPU does it
    const int x0 = (((int)fx % W) + W) % W, x1 = (x0 + 1) % W;
    const int y0 = (((int)fy % H) + H) % H, y1 = (y0 + 1) % H;
    auto c = [&](int x, int y, int k) { return (double)addr[3 * (y * W + x) + k]; };
    double out[3];
    for (int k = 0; k < 3; ++k)
        out[k] = (1 - beta) * ((1 - alpha) * c(x0, y0, k) + alpha * c(x1, y0, k))
               + beta * ((1 - alpha) * c(x0, y1, k) + alpha * c(x1, y1, k));
    return Color(out[0], out[1], out[2]);
}
