// timed_black.cpp - issue 11 attack "forged speed (a)": a lookup ten times
// slower than it needs to be that returns black on the 256 x 256 faces only
// the speed check uses. Before: 5/5 for speed. Verdict now: the answers on
// the timing faces are judged as the sweep judges them: timing-faces-wrong.
#include "EnvironmentMap.h"

#include <cmath>
#include <cstring>

#include <cstdlib>

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
    if (m_FaceWidth >= 256)
        return Color();
    for (volatile int spin = 0; spin < 300; spin = spin + 1) {}
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
