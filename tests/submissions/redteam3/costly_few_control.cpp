// The control for costly_few_skipped_when_timed.cpp, costly_few_wrong_on_timing_faces.cpp and costly_few_vouched_by_readtexture.cpp: a correct lookup, fast except on 7 directions in 1000 (by a hash of the face and (u, v)), where a busy loop costs about 2,000 times the reference's lookup: about 15 times the reference's time per lookup on average (the limit is 8x), and no trick. WORK = 18000 measured 11x on one machine and 6.7x (fast!) on an AMD EPYC (Zen 4, 2026-12-02); 45000 measured 15x there. Verdict: speed fails as slow (the other checks full: 95 of 100).
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

constexpr int WORK = 45000;   // on 7 directions in 1000: about 15 times the reference's time per lookup on average

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

// 7 directions in 1000, by a hash of the face and of (u, v) on a 2^-16 grid
bool costly(int face, double u, double v)
{
    const std::uint64_t x = static_cast<std::uint64_t>(u * 65536.0), y = static_cast<std::uint64_t>(v * 65536.0);
    const std::uint64_t h = (x * 0x9E3779B97F4A7C15ULL) ^ (y * 0xC2B2AE3D27D4EB4FULL) ^ (static_cast<std::uint64_t>(face) << 40);
    return ((h ^ (h >> 29)) * 0xBF58476D1CE4E5B9ULL >> 40) % 1000 < 7;
}

} // namespace

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    const auto [face, u, v] = directionToFace(direction);
    if (costly(face, u, v)) {
        volatile double waste = 0;
        for (int i = 0; i < WORK; ++i)
            waste = waste + i * 1e-9;
    }
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
