// divide_by_zero.cpp - a hostile submission for tests/test_hostile.py: a correct
// solution (tests/submissions/correct/axis_table.cpp) plus one hostile act.
// Act: integer division by zero inside fetchColor for directions near +x.
// Verdict: crash (SIGFPE, "integer division by zero") at that input.
#include "EnvironmentMap.h"

#include <cmath>

// The hostile act happens only for directions close to +x, so the grader must
// attribute it to that input (e.g. fetchColor(Vector3(1, 0, 0))).
static bool hostileTrigger(const Vector3& d)
{
    return d.x > 0.999 * std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
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
    if (hostileTrigger(direction)) {
        volatile int numerator = 7, zero = 0;
        return Color(numerator / zero, 0, 0);
    }
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
