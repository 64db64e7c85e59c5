// off_by_one_x.cpp - a hostile submission for tests/test_hostile.py: a correct
// solution (tests/submissions/correct/axis_table.cpp) plus one hostile act.
// Act (a common bug, not malice): readTexture does not clamp x1 = x0 + 1, so
// u = 1 reads x = W. With alpha = 0 there the value is even right; on the top
// row (v = 1) the read lands past the face's last texel.
// Verdict: out-of-bounds-read at readTexture(face ..., u = 1.0, v = 1.0)
// ("right after the last texel of face ..."), hint "reading x = W ...".
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
    // BUG (on purpose): x1 = x0 + 1 is not clamped, so u = 1 reads x = W.
    const double px = u * m_FaceWidth, py = v * m_FaceHeight;
    const int x0 = clampIndex((int)px, m_FaceWidth), y0 = clampIndex((int)py, m_FaceHeight);
    const int x1 = x0 + 1, y1 = clampIndex(y0 + 1, m_FaceHeight);
    const double a = px - (int)px, b = py - (int)py;
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
