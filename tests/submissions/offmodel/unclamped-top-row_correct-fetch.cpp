// readTexture clamps x1 but not y1 = y0 + 1: at v = 1 (and in the top row)
// it reads the row above the face: the next face's first row inside the
// buffer, past the end of the last face (a crash). fetchColor is right, with
// >= at ties (a tied direction picks a face it touches).
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    const double ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
    if (ax >= ay && ax >= az)
        return d.x > 0 ? readTexture(faceAddress(FACE_POS_X), (1 + d.z / ax) / 2, (1 + d.y / ax) / 2)
                       : readTexture(faceAddress(FACE_NEG_X), (1 - d.z / ax) / 2, (1 + d.y / ax) / 2);
    if (ay >= az)
        return d.y > 0 ? readTexture(faceAddress(FACE_POS_Y), (1 + d.x / ay) / 2, (1 + d.z / ay) / 2)
                       : readTexture(faceAddress(FACE_NEG_Y), (1 + d.x / ay) / 2, (1 - d.z / ay) / 2);
    return d.z > 0 ? readTexture(faceAddress(FACE_POS_Z), (1 + d.x / az) / 2, (1 - d.y / az) / 2)
                   : readTexture(faceAddress(FACE_NEG_Z), (1 + d.x / az) / 2, (1 + d.y / az) / 2);
}

// readTexture:begin
Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const double px = u * m_FaceWidth, py = v * m_FaceHeight;
    const int x0 = std::clamp((int)px, 0, m_FaceWidth - 1), y0 = std::clamp((int)py, 0, m_FaceHeight - 1);
    const int x1 = std::min(x0 + 1, m_FaceWidth - 1), y1 = y0 + 1;       // y1 not clamped
    const double a = px - (int)px, b = py - (int)py;
    auto at = [&](int x, int y) { const float* p = addr + 3 * (y * m_FaceWidth + x); return Color(p[0], p[1], p[2]); };
    return (1 - b) * ((1 - a) * at(x0, y0) + a * at(x1, y0)) + b * ((1 - a) * at(x0, y1) + a * at(x1, y1));
}
// readTexture:end
