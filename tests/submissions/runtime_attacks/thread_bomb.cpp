// thread_bomb.cpp - issue 18 attack "a whole class made ungradable": a correct
// lookup whose static initialiser starts idle threads with 16 KiB stacks (so
// the address-space limit does not stop it) until the system refuses one.
// In privilege-drop mode RLIMIT_NPROC was not set and every worker was uid
// nobody: the container's pids ran out and every student graded beside it
// came out ungradable. Verdict now: the worker's own uid and RLIMIT_NPROC
// stop it at 64 tasks; the refusal is thrown, uncaught in a static
// initialiser, so std::terminate aborts while loading (exception), and
// classmates graded beside it keep full marks. (Capped at 4096 threads, so
// this file cannot take a test machine down should the limit regress.)
#include "EnvironmentMap.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <chrono>
#include <cstddef>
#include <stdexcept>
#include <thread>

namespace {

// pthreads without <pthread.h> (the include policy allows only the standard
// library): <thread> declares them already; std::thread cannot choose its
// stack size.
void* idle(void*)
{
    std::this_thread::sleep_for(std::chrono::hours(1));
    return nullptr;
}

// The bomb: idle threads until the system refuses one, then the refusal thrown.
const int bomb = [] {
    pthread_attr_t attr;
    pthread_attr_init(&attr);
    pthread_attr_setstacksize(&attr, 16384);
    for (int made = 0; made < 4096; ++made) {
        pthread_t thread;
        if (pthread_create(&thread, &attr, idle, nullptr) != 0)
            throw std::runtime_error("no more threads");
    }
    return 0;
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
