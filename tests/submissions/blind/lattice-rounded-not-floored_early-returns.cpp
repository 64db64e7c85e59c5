// TRUTH (written before any grading; checked against tests/helpers/assignment_model.py
// by tests/submissions/blind/check_truth.py):
//   WRONG, in readTexture only. fetchColor is right (early returns per face, ties x, y, z).
//   The mistake: the lower lattice point is ROUNDED, x0 = round(uW), y0 = round(vH), instead
//   of floored, and alpha = uW - x0, beta = vH - y0 are taken from the rounded point (so they
//   lie in [-0.5, 0.5)). Where the fractional part of uW is below 0.5 this is the handout's
//   blend; where it is 0.5 or more, x0 is one texel too far right and alpha is negative: the
//   code extrapolates from texels x0 and x0 + 1 (weights 1 - alpha > 1 and alpha < 0) instead
//   of blending x0 - 1 and x0. Same on v. On a texture that is linear along the axis (a ramp)
//   the extrapolation happens to give the right value; on any other texture it does not.
//   At the last texel (round gives W) the clamp makes it read texel W - 1 alone, which is
//   what the handout reads there too.
//   Expected: read_texture loses most of its 25 points (about 3 in 4 random (u, v) have at least
//   one axis with a fractional part >= 0.5); fetch_sweep, diagnosis, arrows keep full points;
//   renders and stability may lose a little (their colours come through this readTexture);
//   speed keeps. No fetchColor id. A readTexture id, if any, should say the lattice point
//   is not floor(p) / the weights go outside [0, 1] (no catalogue id names rounding; a worked
//   case in numbers is the honest answer).
//   What a student must change: x0 = floor(uW) (or (int) of the non-negative p), y0 likewise.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

namespace {
double toUnit(double s, double m) { return 0.5 * (1.0 + s / m); }
}

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    const double x = direction.x, y = direction.y, z = direction.z;
    const double ax = std::fabs(x), ay = std::fabs(y), az = std::fabs(z);
    if (std::isnan(x) || std::isnan(y) || std::isnan(z))
        return Color();
    if (ax >= ay && ax >= az && ax > 0 && std::isfinite(ax)) {
        if (x > 0)
            return readTexture(faceAddress(FACE_POS_X), toUnit(z, ax), toUnit(y, ax));
        return readTexture(faceAddress(FACE_NEG_X), toUnit(-z, ax), toUnit(y, ax));
    }
    if (ay >= az && ay > 0 && std::isfinite(ay)) {
        if (y > 0)
            return readTexture(faceAddress(FACE_POS_Y), toUnit(x, ay), toUnit(z, ay));
        return readTexture(faceAddress(FACE_NEG_Y), toUnit(x, ay), toUnit(-z, ay));
    }
    if (az > 0 && std::isfinite(az)) {
        if (z > 0)
            return readTexture(faceAddress(FACE_POS_Z), toUnit(x, az), toUnit(-y, az));
        return readTexture(faceAddress(FACE_NEG_Z), toUnit(x, az), toUnit(y, az));
    }
    return Color();
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const double px = u * m_FaceWidth;
    const double py = v * m_FaceHeight;
    // the lattice point nearest to p
    int x0 = (int)std::round(px);
    int y0 = (int)std::round(py);
    const double alpha = px - x0;
    const double beta = py - y0;
    int x1 = x0 + 1, y1 = y0 + 1;
    x0 = std::clamp(x0, 0, m_FaceWidth - 1);
    x1 = std::clamp(x1, 0, m_FaceWidth - 1);
    y0 = std::clamp(y0, 0, m_FaceHeight - 1);
    y1 = std::clamp(y1, 0, m_FaceHeight - 1);
    const float* c00 = addr + 3 * (y0 * m_FaceWidth + x0);
    const float* c10 = addr + 3 * (y0 * m_FaceWidth + x1);
    const float* c01 = addr + 3 * (y1 * m_FaceWidth + x0);
    const float* c11 = addr + 3 * (y1 * m_FaceWidth + x1);
    Color c0((1 - alpha) * c00[0] + alpha * c10[0], (1 - alpha) * c00[1] + alpha * c10[1], (1 - alpha) * c00[2] + alpha * c10[2]);
    Color c1((1 - alpha) * c01[0] + alpha * c11[0], (1 - alpha) * c01[1] + alpha * c11[1], (1 - alpha) * c01[2] + alpha * c11[2]);
    return c0 * (1 - beta) + c1 * beta;
}
