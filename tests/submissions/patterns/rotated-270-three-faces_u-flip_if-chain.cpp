// An if-chain. On +Y, -Y and +Z (u, v) are turned by 90 degrees the other
// way from rotated-90: u = t and v = 1 - s, where (s, t) are the table's
// (u, v) (swapped, and the new v runs the wrong way). Separately, u runs the
// wrong way on +X (the sign in front of z dropped). -X and -Z are right.
// readTexture is the handout's.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    const double ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
    double u, v;
    int face;
    if (ax >= ay && ax >= az && d.x > 0) {
        face = FACE_POS_X; u = (1 - d.z / ax) / 2; v = (1 + d.y / ax) / 2;        // u flipped
    } else if (ax >= ay && ax >= az) {
        face = FACE_NEG_X; u = (1 - d.z / ax) / 2; v = (1 + d.y / ax) / 2;
    } else if (ay >= az && d.y > 0) {
        const double s = (1 + d.x / ay) / 2, t = (1 + d.z / ay) / 2;
        face = FACE_POS_Y; u = t; v = 1 - s;
    } else if (ay >= az) {
        const double s = (1 + d.x / ay) / 2, t = (1 - d.z / ay) / 2;
        face = FACE_NEG_Y; u = t; v = 1 - s;
    } else if (d.z > 0) {
        const double s = (1 + d.x / az) / 2, t = (1 - d.y / az) / 2;
        face = FACE_POS_Z; u = t; v = 1 - s;
    } else {
        face = FACE_NEG_Z; u = (1 + d.x / az) / 2; v = (1 + d.y / az) / 2;
    }
    return readTexture(faceAddress(face), u, v);
}

// readTexture:begin
Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const double px = u * m_FaceWidth, py = v * m_FaceHeight;
    const int x0 = std::clamp((int)px, 0, m_FaceWidth - 1), y0 = std::clamp((int)py, 0, m_FaceHeight - 1);
    const int x1 = std::min(x0 + 1, m_FaceWidth - 1), y1 = std::min(y0 + 1, m_FaceHeight - 1);
    const double a = px - (int)px, b = py - (int)py;
    auto at = [&](int x, int y) { const float* p = addr + 3 * (y * m_FaceWidth + x); return Color(p[0], p[1], p[2]); };
    return (1 - b) * ((1 - a) * at(x0, y0) + a * at(x1, y0)) + b * ((1 - a) * at(x0, y1) + a * at(x1, y1));
}
// readTexture:end
