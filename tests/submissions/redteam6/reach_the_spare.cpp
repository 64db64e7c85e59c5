// While one worker runs, the runner keeps the next one prepared: its sandbox set up and the worker waiting at a gate (a pipe) for the texture size (in the first form, a root shell waiting at its stdin). This submission, given the spare's pid as fetchColor(pid, 0, 54321), looks for it in /proc and opens its fd 0 (/proc/pid/fd/0: the first form's gate) to read the size before the grader writes it; fetchColor(pid, 0, 54322) sends it SIGKILL; fetchColor(0, 0, 54323) looks at its own stdin (the gate, were it inherited) and counts the pipes it holds besides fds 1 and 2. Verdict: it sees no such process and opens nothing (0, 0, 0), the signal is a forbidden-syscall failure, its stdin is /dev/null and it holds only its request and reply pipes and the worker's scratch pair (0, 4, 0); the spare then starts with the right size and answers correctly.
#include "EnvironmentMap.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <sched.h>
#include <csignal>
#include <fcntl.h>
#include <string>
#include <sys/stat.h>
#include <unistd.h>

namespace {

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

// What this process can do to the process `pid` (the runner's spare shell).
Color reach(int pid, int what)
{
    if (what == 54321) {
        const std::string proc = "/proc/" + std::to_string(pid);
        struct stat st {};
        const double seen = stat(proc.c_str(), &st) == 0 ? 1.0 : 0.0;
        const int gate = open((proc + "/fd/0").c_str(), O_RDONLY | O_NONBLOCK);
        double stolen = 0.0;
        if (gate >= 0) {
            char line[64];
            const ssize_t got = read(gate, line, sizeof line);   // the size line, before the grader writes it
            stolen = got > 0 ? static_cast<double>(got) : 0.0;
        }
        return Color(seen, gate >= 0 ? 1.0 : 0.0, stolen);
    }
    if (what == 54322) {
        kill(pid, SIGKILL);
        return Color(1.0, 1.0, 1.0);
    }
    struct stat in {};
    const double notNull = fstat(0, &in) == 0 && S_ISCHR(in.st_mode) ? 0.0 : 1.0;   // 0: stdin is /dev/null
    int pipes = 0;
    for (int fd = 0; fd < 1024; ++fd) {
        struct stat st {};
        if (fd != 1 && fd != 2 && fstat(fd, &st) == 0 && S_ISFIFO(st.st_mode)) {
            ++pipes;
        }
    }
    return Color(notNull, static_cast<double>(pipes), 0.0);
}

} // namespace

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    if (direction.y == 0 && direction.z >= 54321 && direction.z <= 54323) {
        // The grader never asks these: a stand-in for guessing the spare's pid.
        return reach(static_cast<int>(direction.x), static_cast<int>(direction.z));
    }
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
