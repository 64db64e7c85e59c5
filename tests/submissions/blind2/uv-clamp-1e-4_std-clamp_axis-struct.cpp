// TRUTH (written before any grading; checked against tests/helpers/assignment_model.py
// by tests/submissions/blind2/truth/check_truth.py):
//   WRONG, in fetchColor only. Faces and the (u, v) table are right (a small struct per
//   major axis, x before y before z at ties; zero, NaN and infinite directions return
//   black), but before the call
//       u = std::clamp(u, kEdge, 1.0 - kEdge); v = std::clamp(v, kEdge, 1.0 - kEdge);
//   with kEdge = 1e-4 ("stay off the seam"), on every face. So (u, v) within 1e-4 of a
//   face's border is asked moved inward onto u, v = 1e-4 or 1 - 1e-4; everything else is
//   unchanged. End to end the colour changes by at most 1e-4 * W of a texel step there
//   (on the last row/column, where the handout reads one texel alone, not at all).
//   readTexture is the handout's.
//   Expected: fetch_sweep loses at most a little (edges, corners, axes-near-border
//   directions); read_texture, arrows keep full points. Diagnosis: uv-clamped-inward on
//   every face (no other fetchColor id: not uv-inset, which scales all of (u, v), not
//   uv-offset, coordinate-wraps; no readTexture id).
//   What a student must change: drop the clamp, or clamp to [0, 1].
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

namespace {
constexpr double kEdge = 1e-4;

struct Pick { int face; double m, s, t; };

Pick pick(double x, double y, double z)
{
    const double ax = std::fabs(x), ay = std::fabs(y), az = std::fabs(z);
    if (ax >= ay && ax >= az)
        return x > 0 ? Pick{FACE_POS_X, ax, z, y} : Pick{FACE_NEG_X, ax, -z, y};
    if (ay >= az)
        return y > 0 ? Pick{FACE_POS_Y, ay, x, z} : Pick{FACE_NEG_Y, ay, x, -z};
    return z > 0 ? Pick{FACE_POS_Z, az, x, -y} : Pick{FACE_NEG_Z, az, x, y};
}
}  // namespace

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    if (!std::isfinite(direction.x) || !std::isfinite(direction.y) || !std::isfinite(direction.z))
        return Color();
    const Pick p = pick(direction.x, direction.y, direction.z);
    if (p.m == 0)
        return Color();
    double u = (1 + p.s / p.m) / 2;
    double v = (1 + p.t / p.m) / 2;
    u = std::clamp(u, kEdge, 1.0 - kEdge);   // stay off the seam
    v = std::clamp(v, kEdge, 1.0 - kEdge);
    return readTexture(faceAddress(p.face), u, v);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const double px = u * m_FaceWidth;
    const double py = v * m_FaceHeight;
    const int x0 = std::clamp((int)std::floor(px), 0, m_FaceWidth - 1);
    const int x1 = std::clamp((int)std::floor(px) + 1, 0, m_FaceWidth - 1);
    const int y0 = std::clamp((int)std::floor(py), 0, m_FaceHeight - 1);
    const int y1 = std::clamp((int)std::floor(py) + 1, 0, m_FaceHeight - 1);
    const double alpha = px - std::floor(px);
    const double beta = py - std::floor(py);
    auto at = [&](int x, int y) {
        const float* t = addr + 3 * (y * m_FaceWidth + x);
        return Color(t[0], t[1], t[2]);
    };
    const Color c0 = (1 - alpha) * at(x0, y0) + alpha * at(x1, y0);
    const Color c1 = (1 - alpha) * at(x0, y1) + alpha * at(x1, y1);
    return (1 - beta) * c0 + beta * c1;
}
