// self_waking_spinner.cpp - issue 32, tried as a motivated student would: the
// idle spinner plus a POSIX timer that sends the worker SIGCONT every
// millisecond, so that the grader's stop between calls would last a
// millisecond at most. Verdict: the stop holds (Linux 6.18: a SIGCONT a
// timer generates does not resume a process stopped by SIGSTOP); it prints
// "waker: 0" (the timer was set), and the tests assert it uses no CPU time
// between calls, so a kernel where the timer does resume it is caught.
#include "EnvironmentMap.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstddef>
#include <ctime>
#include <thread>

namespace {

std::atomic<int> callsInFlight{0};

const int waker = [] {
    sigevent event{};
    event.sigev_notify = SIGEV_SIGNAL;
    event.sigev_signo = SIGCONT;
    timer_t timer;
    if (timer_create(CLOCK_MONOTONIC, &event, &timer) != 0)
        return -1;
    itimerspec every{};
    every.it_interval.tv_nsec = 1000000;
    every.it_value.tv_nsec = 1000000;
    const int set = timer_settime(timer, 0, &every, nullptr);
    std::printf("waker: %d\n", set);
    return set;
}();

const int spinners = [] {
    int started = 0;
    for (; started < 63; ++started) {
        try {
            std::thread([] {
                volatile unsigned long spins = 0;
                for (;;) {
                    if (callsInFlight.load(std::memory_order_relaxed) == 0)
                        ++spins;
                    else
                        std::this_thread::sleep_for(std::chrono::milliseconds(1));   // idle while asked
                }
            }).detach();
        } catch (...) {
            break;      // the task limit: as many as it allows
        }
    }
    return started;
}();

struct InCall
{
    InCall() { callsInFlight.fetch_add(1); }
    ~InCall() { callsInFlight.fetch_sub(1); }
};

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
    const InCall call;
    const auto [face, u, v] = directionToFace(direction);
    return readTexture(faceAddress(face), u, v);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const InCall call;
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
