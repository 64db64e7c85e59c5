// pipe_filler.cpp - issue 32 attack "the grader blamed, the student's grade 0":
// a correct lookup whose static initialiser opens pipes until the system
// refuses one and fills each (kernel memory: outside RLIMIT_AS and RSS, but
// charged to the container's memory cgroup). With 20,000 descriptors in a
// 285 MiB container the OOM killer took the grader. Verdict now: RLIMIT_NOFILE
// (64) stops it at a few pipes (it prints how many, which the tests read), the
// worker's oom_score_adj 1000 makes it the OOM killer's first choice where
// memory still runs out, and its correct lookup earns full marks.
// (Capped at 100,000 pipes, so this file cannot take a test machine down
// should every limit regress.)
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>

// POSIX, without <unistd.h> (the include policy allows only the standard library).
extern "C" int pipe2(int* fds, int flags) noexcept;
extern "C" long write(int fd, const void* data, unsigned long size) noexcept;

namespace {

const int pipesHeld = [] {
    static char chunk[1 << 16];
    const int nonBlocking = 04000;   // O_NONBLOCK: a full pipe refuses instead of waiting
    int held = 0;
    for (; held < 100000; ++held) {
        int fds[2];
        if (pipe2(fds, nonBlocking) != 0)
            break;
        while (write(fds[1], chunk, sizeof chunk) > 0) {
        }
    }
    std::printf("pipes held: %d\n", held);
    return held;
}();

struct FaceCoord
{
    int face;
    double u;
    double v;
};

// Where a direction meets the cube: the face and (u, v) of README.md's table.
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

} // namespace

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    const auto [face, u, v] = directionToFace(direction);
    return readTexture(faceAddress(face), u, v);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const double px = u * m_FaceWidth;
    const double py = v * m_FaceHeight;
    const int ix = static_cast<int>(px);
    const int iy = static_cast<int>(py);
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
