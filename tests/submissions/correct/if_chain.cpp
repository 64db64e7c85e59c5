// A correct solution written as if-chains, as the handout's code style suggests.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

using std::max;
using std::min;

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    const double x = direction.x, y = direction.y, z = direction.z;
    const double ax = std::fabs(x), ay = std::fabs(y), az = std::fabs(z);
    int face;
    double u, v;
    if (ax >= ay && ax >= az) {
        if (x > 0) {
            face = FACE_POS_X;
            u = (1 + z / ax) / 2;
            v = (1 + y / ax) / 2;
        } else {
            face = FACE_NEG_X;
            u = (1 - z / ax) / 2;
            v = (1 + y / ax) / 2;
        }
    } else if (ay >= az) {
        if (y > 0) {
            face = FACE_POS_Y;
            u = (1 + x / ay) / 2;
            v = (1 + z / ay) / 2;
        } else {
            face = FACE_NEG_Y;
            u = (1 + x / ay) / 2;
            v = (1 - z / ay) / 2;
        }
    } else {
        if (z > 0) {
            face = FACE_POS_Z;
            u = (1 + x / az) / 2;
            v = (1 - y / az) / 2;
        } else {
            face = FACE_NEG_Z;
            u = (1 + x / az) / 2;
            v = (1 + y / az) / 2;
        }
    }
    return readTexture(faceAddress(face), u, v);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const double px = u * m_FaceWidth;
    const double py = v * m_FaceHeight;
    const int ix = (int)px;
    const int iy = (int)py;
    const double alpha = px - ix;
    const double beta = py - iy;
    const int x0 = max(0, min(ix, m_FaceWidth - 1));
    const int x1 = max(0, min(ix + 1, m_FaceWidth - 1));
    const int y0 = max(0, min(iy, m_FaceHeight - 1));
    const int y1 = max(0, min(iy + 1, m_FaceHeight - 1));
    const float* p00 = addr + 3 * (y0 * m_FaceWidth + x0);
    const float* p10 = addr + 3 * (y0 * m_FaceWidth + x1);
    const float* p01 = addr + 3 * (y1 * m_FaceWidth + x0);
    const float* p11 = addr + 3 * (y1 * m_FaceWidth + x1);
    const Color c00(p00[0], p00[1], p00[2]);
    const Color c10(p10[0], p10[1], p10[2]);
    const Color c01(p01[0], p01[1], p01[2]);
    const Color c11(p11[0], p11[1], p11[2]);
    const Color c0 = c00 * (1 - alpha) + c10 * alpha;
    const Color c1 = c01 * (1 - alpha) + c11 * alpha;
    return c0 * (1 - beta) + c1 * beta;
}
