// Thirty times slower than the reference everywhere, except on the speed check's timing faces (256 x 256, colour = 0.5 + 0.5 x the unit direction through each texel centre: told by their size and one texel), where it skips the texels and computes that closed form at the (clamped) lattice position: within float rounding of bilinear filtering on so smooth a texture, so the timed colours "match". Verdict (secure): speed fails (slow or timed-output-wrong), the other checks full.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace {

struct FaceCoord
{
    int face;
    double u;
    double v;
};

FaceCoord directionToFace(const Vector3& d)
{
    const double ax = std::abs(d.x), ay = std::abs(d.y), az = std::abs(d.z);
    auto toUnit = [](double s, double m) { return (s / m + 1.0) / 2.0; };
    if (ax >= ay && ax >= az) {
        return d.x > 0 ? FaceCoord{FACE_POS_X, toUnit(d.z, ax), toUnit(d.y, ax)}
                       : FaceCoord{FACE_NEG_X, toUnit(-d.z, ax), toUnit(d.y, ax)};
    }
    if (ay >= az) {
        return d.y > 0 ? FaceCoord{FACE_POS_Y, toUnit(d.x, ay), toUnit(d.z, ay)}
                       : FaceCoord{FACE_NEG_Y, toUnit(d.x, ay), toUnit(-d.z, ay)};
    }
    return d.z > 0 ? FaceCoord{FACE_POS_Z, toUnit(d.x, az), toUnit(-d.y, az)}
                   : FaceCoord{FACE_NEG_Z, toUnit(d.x, az), toUnit(d.y, az)};
}

// The point of face `face` at plane coordinates (s, t) = (2u - 1, 2v - 1).
void facePoint(int face, double s, double t, double out[3])
{
    switch (face) {
    case FACE_POS_X: out[0] = 1; out[1] = t; out[2] = s; break;
    case FACE_NEG_X: out[0] = -1; out[1] = t; out[2] = -s; break;
    case FACE_POS_Y: out[0] = s; out[1] = 1; out[2] = t; break;
    case FACE_NEG_Y: out[0] = s; out[1] = -1; out[2] = -t; break;
    case FACE_POS_Z: out[0] = s; out[1] = -t; out[2] = 1; break;
    default: out[0] = s; out[1] = t; out[2] = -1; break;
    }
}

// Continuous texel-centre coordinate of lattice position p, clamped as the filter clamps.
double centre(double c, int n)
{
    const double p = std::clamp(c * n, 0.0, n - 1.0);
    return 2.0 * (p + 0.5) / n - 1.0;
}

} // namespace

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    const auto [face, u, v] = directionToFace(direction);
    if (m_FaceWidth == 256 && m_FaceHeight == 256) {
        double d[3];
        facePoint(FACE_POS_X, 2.0 * (0.5 / 256) - 1.0, 2.0 * (0.5 / 256) - 1.0, d);
        const double n = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (std::abs(m_Texels[0] - (0.5 + 0.5 * d[0] / n)) < 1e-6) {
            // The timing faces: their colour in closed form, no texel read.
            facePoint(face, centre(u, 256), centre(v, 256), d);
            const double k = 0.5 / std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            return {static_cast<float>(0.5 + k * d[0]), static_cast<float>(0.5 + k * d[1]),
                    static_cast<float>(0.5 + k * d[2])};
        }
    }
    volatile double waste = 0;
    for (int i = 0; i < 6000; ++i)   // about thirty times slower everywhere else
        waste = waste + i * 1e-9;
    return readTexture(faceAddress(face), u, v);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const double px = u * m_FaceWidth;
    const double py = v * m_FaceHeight;
    const int ix = static_cast<int>(std::floor(px));
    const int iy = static_cast<int>(std::floor(py));
    const double alpha = px - ix;
    const double beta = py - iy;

    const auto texel = [&](int x, int y) -> Color {
        x = std::clamp(x, 0, m_FaceWidth - 1);
        y = std::clamp(y, 0, m_FaceHeight - 1);
        const float* t = addr + 3 * (static_cast<std::ptrdiff_t>(y) * m_FaceWidth + x);
        return {t[0], t[1], t[2]};
    };
    const Color c0 = (1.0 - alpha) * texel(ix, iy) + alpha * texel(ix + 1, iy);
    const Color c1 = (1.0 - alpha) * texel(ix, iy + 1) + alpha * texel(ix + 1, iy + 1);
    return (1.0 - beta) * c0 + beta * c1;
}
