// clock_got.cpp - issue 11 attack "forged speed (c)": slow lookups, and a
// static initialiser that makes the worker's own pages writable to redirect
// its clock_gettime GOT entry (the worker once timed lookups with its own
// clock). Verdict now: the worker's pages keep their protection (the filter
// refuses the mprotect while loading: forbidden-syscall), and the speed check
// does not read any clock inside the worker anyway.
#include "EnvironmentMap.h"

#include <cmath>
#include <cstring>

extern "C" {
int mprotect(void* addr, unsigned long len, int prot);
int open(const char* path, int flags, ...);
long read(int fd, void* buf, unsigned long n);
long write(int fd, const void* buf, unsigned long n);
int close(int fd);
}
extern "C" unsigned long getauxval(unsigned long type);

namespace {
struct Patch {
    Patch()
    {
        unsigned long phdr = getauxval(3 /* AT_PHDR */);
        unsigned long first = phdr & ~4095UL;
        for (unsigned long page = first; page < first + (64UL << 10); page += 4096)
            mprotect((void*)page, 4096, 3 /* PROT_READ | PROT_WRITE */);
    }
} patch;
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
    for (volatile int spin = 0; spin < 3000; spin = spin + 1) {}
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
