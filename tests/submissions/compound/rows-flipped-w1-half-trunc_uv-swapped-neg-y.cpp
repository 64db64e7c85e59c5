// Compound zoo. fetchColor (switch on the major axis): u and v swapped on -Y.
// readTexture: rows read top-down (row H-1-y), the lattice scaled by W - 1,
// shifted half a texel down (p = u(W-1) - 0.5) and truncated with (int), so
// for p in (-0.5, 0) x0 = 0 and the weight goes negative (it extrapolates).
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

static int clampi(int i, int n) { return std::max(0, std::min(i, n - 1)); }

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    const double ax = std::fabs(direction.x), ay = std::fabs(direction.y), az = std::fabs(direction.z);
    const int axis = (ax >= ay && ax >= az) ? 0 : (ay >= az ? 1 : 2);
    int face = 0;
    double u = 0, v = 0;
    switch (axis) {
    case 0:
        face = direction.x > 0 ? FACE_POS_X : FACE_NEG_X;
        u = 0.5 * (1 + (direction.x > 0 ? direction.z : -direction.z) / ax);
        v = 0.5 * (1 + direction.y / ax);
        break;
    case 1:
        if (direction.y > 0) {
            face = FACE_POS_Y;
            u = 0.5 * (1 + direction.x / ay);
            v = 0.5 * (1 + direction.z / ay);
        } else {
            face = FACE_NEG_Y;
            v = 0.5 * (1 + direction.x / ay);     // swapped
            u = 0.5 * (1 - direction.z / ay);
        }
        break;
    default:
        face = direction.z > 0 ? FACE_POS_Z : FACE_NEG_Z;
        u = 0.5 * (1 + direction.x / az);
        v = 0.5 * (1 + (direction.z > 0 ? -direction.y : direction.y) / az);
    }
    return readTexture(faceAddress(face), u, v);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const double px = u * (m_FaceWidth - 1) - 0.5;
    const double py = v * (m_FaceHeight - 1) - 0.5;
    const int ix = (int)px, iy = (int)py;
    const double a = px - ix, b = py - iy;
    const int x0 = clampi(ix, m_FaceWidth), x1 = clampi(ix + 1, m_FaceWidth);
    const int y0 = m_FaceHeight - 1 - clampi(iy, m_FaceHeight);      // rows top-down
    const int y1 = m_FaceHeight - 1 - clampi(iy + 1, m_FaceHeight);
    double rgb[3];
    for (int k = 0; k < 3; ++k) {
        const double c0 = (1 - a) * addr[3 * (y0 * m_FaceWidth + x0) + k] + a * addr[3 * (y0 * m_FaceWidth + x1) + k];
        const double c1 = (1 - a) * addr[3 * (y1 * m_FaceWidth + x0) + k] + a * addr[3 * (y1 * m_FaceWidth + x1) + k];
        rgb[k] = (1 - b) * c0 + b * c1;
    }
    return Color(rgb[0], rgb[1], rgb[2]);
}
