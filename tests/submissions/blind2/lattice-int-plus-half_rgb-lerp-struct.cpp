// TRUTH (written before any grading; checked against tests/helpers/assignment_model.py
// by tests/submissions/blind2/truth/check_truth.py):
//   WRONG, in readTexture only. fetchColor is right (a FaceUV struct from a switch on the
//   major axis, x before y before z at ties; zero, NaN and infinite directions return black).
//   The mistake: the lattice point is ROUNDED with x0 = (int)(uW + 0.5), y0 = (int)(vH + 0.5)
//   (p >= 0, so this is round-half-up), and alpha = uW - x0, beta = vH - y0 are taken from
//   the rounded point, so they lie in [-0.5, 0.5). Then x1 = min(x0 + 1, W - 1),
//   x0 = min(x0, W - 1) (same for y) and the handout's blend, written with a lerp helper
//   a + (b - a) t on an RGB struct. Where frac(uW) < 0.5 this is the handout's blend;
//   where frac(uW) >= 0.5 it extrapolates from x0 = floor(uW) + 1 and x0 + 1 with a
//   negative alpha (or, where x0 + 1 is clamped, reads column W - 1 alone for
//   uW in [W - 1.5, W - 1)). Same on v.
//   Expected: read_texture loses points; fetch_sweep, arrows keep full points; renders and
//   stability may lose a little (their colours come through this readTexture); speed keeps.
//   Diagnosis: lattice-rounded (and no fetchColor id, no other readTexture id).
//   What a student must change: x0 = (int)floor(uW), y0 = (int)floor(vH).
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

namespace {

struct FaceUV { int face; double u, v; };
struct RGB { double r, g, b; };

RGB texelAt(const float* addr, int w, int x, int y)
{
    const float* t = addr + 3 * (y * w + x);
    return RGB{t[0], t[1], t[2]};
}

RGB lerp(const RGB& a, const RGB& b, double t)
{
    return RGB{a.r + (b.r - a.r) * t, a.g + (b.g - a.g) * t, a.b + (b.b - a.b) * t};
}

bool project(double x, double y, double z, FaceUV& out)
{
    if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z))
        return false;
    const double ax = std::fabs(x), ay = std::fabs(y), az = std::fabs(z);
    const int axis = (ax >= ay && ax >= az) ? 0 : (ay >= az ? 1 : 2);
    const double m = axis == 0 ? ax : (axis == 1 ? ay : az);
    if (m == 0.0)
        return false;
    switch (axis) {
    case 0:
        if (x > 0) out = FaceUV{FACE_POS_X, (1 + z / m) / 2, (1 + y / m) / 2};
        else       out = FaceUV{FACE_NEG_X, (1 - z / m) / 2, (1 + y / m) / 2};
        break;
    case 1:
        if (y > 0) out = FaceUV{FACE_POS_Y, (1 + x / m) / 2, (1 + z / m) / 2};
        else       out = FaceUV{FACE_NEG_Y, (1 + x / m) / 2, (1 - z / m) / 2};
        break;
    default:
        if (z > 0) out = FaceUV{FACE_POS_Z, (1 + x / m) / 2, (1 - y / m) / 2};
        else       out = FaceUV{FACE_NEG_Z, (1 + x / m) / 2, (1 + y / m) / 2};
        break;
    }
    return true;
}

}  // namespace

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    FaceUV f;
    if (!project(direction.x, direction.y, direction.z, f))
        return Color(0.0, 0.0, 0.0);
    return readTexture(faceAddress(f.face), f.u, f.v);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const int W = m_FaceWidth, H = m_FaceHeight;
    const double px = u * W, py = v * H;
    // nearest lattice point
    int x0 = (int)(px + 0.5);
    int y0 = (int)(py + 0.5);
    const double alpha = px - x0;
    const double beta = py - y0;
    const int x1 = std::max(0, std::min(x0 + 1, W - 1));
    const int y1 = std::max(0, std::min(y0 + 1, H - 1));
    x0 = std::max(0, std::min(x0, W - 1));
    y0 = std::max(0, std::min(y0, H - 1));
    const RGB c0 = lerp(texelAt(addr, W, x0, y0), texelAt(addr, W, x1, y0), alpha);
    const RGB c1 = lerp(texelAt(addr, W, x0, y1), texelAt(addr, W, x1, y1), alpha);
    const RGB c = lerp(c0, c1, beta);
    return Color(c.r, c.g, c.b);
}
