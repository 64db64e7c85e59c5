// TRUTH (written before any grading; checked against tests/helpers/assignment_model.py
// by tests/submissions/blind2/truth/check_truth.py):
//   WRONG, in fetchColor only. Faces and the (u, v) table are right (if-chain, x before y
//   before z at ties; zero, NaN and infinite directions return black), but u and v are then
//   clamped to the TEXEL CENTRES of the outer texels, as GL's clamp-to-edge would:
//       u in [0.5/W, 1 - 0.5/W], v in [0.5/H, 1 - 0.5/H]   (W, H = faceWidth(), faceHeight())
//   on every face. In this assignment texel x sits at u = x/W (no half-texel offset:
//   readTexture's p = (uW, vH)), so the clamp moves every (u, v) in the outer half texel.
//   End to end: near u = 0 (uW < 0.5) the code reads 0.5 c(0) + 0.5 c(1) where the handout
//   blends with alpha = uW; near u = 1 (uW > W - 0.5) both read column W - 1 alone, so the
//   colour is unchanged there. Same on v.
//   readTexture is the handout's.
//   Expected: fetch_sweep loses a little (the u = 0 and v = 0 borders); read_texture and
//   arrows keep full points. What it is: uv-clamped-inward, with eps = half a texel
//   (0.5/W: it depends on the face size). It is NOT half-texel-offset (readTexture is
//   right and (u, v) inside the band are unchanged), not uv-offset or uv-inset (no
//   shift or scale of the interior); no readTexture id.
//   What a student must change: drop the clamp (or clamp to [0, 1]).
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

using std::max;
using std::min;

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    const double x = direction.x, y = direction.y, z = direction.z;
    if (std::isnan(x + y + z) || std::isinf(x) || std::isinf(y) || std::isinf(z))
        return Color(0, 0, 0);
    const double ax = std::fabs(x), ay = std::fabs(y), az = std::fabs(z);
    int face;
    double u, v;
    if (ax >= ay && ax >= az && ax > 0) {
        face = x > 0 ? FACE_POS_X : FACE_NEG_X;
        u = x > 0 ? 0.5 * (1 + z / ax) : 0.5 * (1 - z / ax);
        v = 0.5 * (1 + y / ax);
    } else if (ay >= az && ay > 0) {
        face = y > 0 ? FACE_POS_Y : FACE_NEG_Y;
        u = 0.5 * (1 + x / ay);
        v = y > 0 ? 0.5 * (1 + z / ay) : 0.5 * (1 - z / ay);
    } else if (az > 0) {
        face = z > 0 ? FACE_POS_Z : FACE_NEG_Z;
        u = 0.5 * (1 + x / az);
        v = z > 0 ? 0.5 * (1 - y / az) : 0.5 * (1 + y / az);
    } else {
        return Color(0, 0, 0);
    }
    // sample at texel centres so the outer texels are not blended with nothing
    const double hu = 0.5 / faceWidth(), hv = 0.5 / faceHeight();
    u = min(max(u, hu), 1.0 - hu);
    v = min(max(v, hv), 1.0 - hv);
    return readTexture(faceAddress(face), u, v);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const double px = u * m_FaceWidth, py = v * m_FaceHeight;
    const int fx = (int)std::floor(px), fy = (int)std::floor(py);
    const int x0 = max(0, min(fx, m_FaceWidth - 1)), x1 = max(0, min(fx + 1, m_FaceWidth - 1));
    const int y0 = max(0, min(fy, m_FaceHeight - 1)), y1 = max(0, min(fy + 1, m_FaceHeight - 1));
    const double a = px - fx, b = py - fy;
    const float* r0 = addr + 3 * y0 * m_FaceWidth;
    const float* r1 = addr + 3 * y1 * m_FaceWidth;
    double c[3];
    for (int k = 0; k < 3; ++k) {
        const double lo = (1 - a) * r0[3 * x0 + k] + a * r0[3 * x1 + k];
        const double hi = (1 - a) * r1[3 * x0 + k] + a * r1[3 * x1 + k];
        c[k] = (1 - b) * lo + b * hi;
    }
    return Color(c[0], c[1], c[2]);
}
