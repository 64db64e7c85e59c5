// Compound zoo. fetchColor (face table): v runs the wrong way on +Z (v = (1 + y/m)/2
// there). readTexture: the weights are ints, so alpha = beta = 0 always and
// it returns c00 (one texel, never a blend).
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

namespace {
// major axis, sign; u axis, u sign; v axis, v sign
const int kTable[6][6] = {
    {0, +1, 2, +1, 1, +1},
    {0, -1, 2, -1, 1, +1},
    {1, +1, 0, +1, 2, +1},
    {1, -1, 0, +1, 2, -1},
    {2, +1, 0, +1, 1, +1},   // +Z: should be v sign -1
    {2, -1, 0, +1, 1, +1},
};
}

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    const double d[3] = {direction.x, direction.y, direction.z};
    int major = 0;
    for (int i = 1; i < 3; ++i)
        if (std::fabs(d[i]) > std::fabs(d[major])) major = i;
    const int face = 2 * major + (d[major] < 0 ? 1 : 0);
    const int* t = kTable[face];
    const double m = std::fabs(d[major]);
    const double u = 0.5 * (1 + t[3] * d[t[2]] / m);
    const double v = 0.5 * (1 + t[5] * d[t[4]] / m);
    return readTexture(faceAddress(face), u, v);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    double px = u * m_FaceWidth, py = v * m_FaceHeight;
    int x0 = (int)px, y0 = (int)py;
    int alpha = px - x0, beta = py - y0;            // int: always 0
    int x1 = std::min(x0 + 1, m_FaceWidth - 1), y1 = std::min(y0 + 1, m_FaceHeight - 1);
    x0 = std::min(x0, m_FaceWidth - 1);
    y0 = std::min(y0, m_FaceHeight - 1);
    Color c00(addr[3 * (y0 * m_FaceWidth + x0)], addr[3 * (y0 * m_FaceWidth + x0) + 1], addr[3 * (y0 * m_FaceWidth + x0) + 2]);
    Color c10(addr[3 * (y0 * m_FaceWidth + x1)], addr[3 * (y0 * m_FaceWidth + x1) + 1], addr[3 * (y0 * m_FaceWidth + x1) + 2]);
    Color c01(addr[3 * (y1 * m_FaceWidth + x0)], addr[3 * (y1 * m_FaceWidth + x0) + 1], addr[3 * (y1 * m_FaceWidth + x0) + 2]);
    Color c11(addr[3 * (y1 * m_FaceWidth + x1)], addr[3 * (y1 * m_FaceWidth + x1) + 1], addr[3 * (y1 * m_FaceWidth + x1) + 2]);
    Color c0 = c00 * (1 - alpha) + c10 * alpha;
    Color c1 = c01 * (1 - alpha) + c11 * alpha;
    return c0 * (1 - beta) + c1 * beta;
}
