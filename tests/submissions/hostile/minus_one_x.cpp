// minus_one_x.cpp - a hostile submission for tests/test_hostile.py: a correct
// solution (tests/submissions/correct/axis_table.cpp) plus one hostile act.
// Act (a common bug): readTexture does not clamp x0 below, so u = 0 reads
// x = -1; on the bottom row (v = 0) that is before the face's first texel.
// Verdict (faces placed with a guard page before them): out-of-bounds-read at
// readTexture(face ..., u = 0.0, v = 0.0), "12 bytes before the first texel".
#include "EnvironmentMap.h"

#include <cmath>

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
    // BUG (on purpose): texel centres at half-integers, and x0 is not clamped
    // below, so u = 0 reads x = -1.
    const double px = u * m_FaceWidth - 0.5, py = v * m_FaceHeight - 0.5;
    const int x0 = (int)std::floor(px), y0 = clampIndex((int)std::floor(py), m_FaceHeight);
    const int x1 = clampIndex(x0 + 1, m_FaceWidth), y1 = clampIndex(y0 + 1, m_FaceHeight);
    const double a = px - std::floor(px), b = py - std::floor(py);
    const float* t00 = addr + 3 * (y0 * m_FaceWidth + x0);
    const float* t10 = addr + 3 * (y0 * m_FaceWidth + x1);
    const float* t01 = addr + 3 * (y1 * m_FaceWidth + x0);
    const float* t11 = addr + 3 * (y1 * m_FaceWidth + x1);
    Color c;
    c.r = (1 - b) * ((1 - a) * t00[0] + a * t10[0]) + b * ((1 - a) * t01[0] + a * t11[0]);
    c.g = (1 - b) * ((1 - a) * t00[1] + a * t10[1]) + b * ((1 - a) * t01[1] + a * t11[1]);
    c.b = (1 - b) * ((1 - a) * t00[2] + a * t10[2]) + b * ((1 - a) * t01[2] + a * t11[2]);
    return c;
}
