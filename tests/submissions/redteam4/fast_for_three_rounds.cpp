// slow_control.cpp's lookup (a correct one, about 20 times the reference's time per lookup: the limit is 8x), without its busy loop for the first 330,000 fetchColor calls of a process: the speed check's first three rounds (2 x 50,000 timed, 5,000 untimed, 5,000 + 1,024 recorded a round) in its fresh worker run at the reference's speed, honestly computed, and the check settles there (the ratio is 4x or more under the limit: SETTLED_ROUNDS, SETTLED_FACTOR); any later call is 20x. Its truth is the control's: slow (speed 0). Verdict (secure): speed fails (slow), as for the control, the whole grading no higher than the control's (95 of 100).
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

constexpr int WORK = 375;
// Lookups a process makes before the busy loop starts: the speed check's first three rounds (SETTLED_ROUNDS) in its fresh worker.
constexpr unsigned long FAST_CALLS = 330000;

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

unsigned long g_calls = 0;   // fetchColor calls in this process

} // namespace

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    const auto [face, u, v] = directionToFace(direction);
    volatile double waste = 0;
    const int work = g_calls++ < FAST_CALLS ? 0 : WORK;
    for (int i = 0; i < work; ++i)   // about 20 times the reference's time per lookup
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
