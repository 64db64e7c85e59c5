// Compound zoo. fetchColor (signed major components, face table of
// addresses): +Y and -Y swapped in the table, and -X's u runs the wrong way.
// readTexture: the starting code's nearest texel, left as it was.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    static const int faceOf[3][2] = {{FACE_POS_X, FACE_NEG_X}, {FACE_NEG_Y, FACE_POS_Y}, {FACE_POS_Z, FACE_NEG_Z}};
    const double ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
    double u, v;
    int face;
    if (ax >= ay && ax >= az) {
        face = faceOf[0][d.x < 0];
        u = d.x > 0 ? (1 + d.z / ax) / 2 : (1 + d.z / ax) / 2;   // -X: should be 1 - z/m
        v = (1 + d.y / ax) / 2;
    } else if (ay >= az) {
        face = faceOf[1][d.y < 0];
        u = (1 + d.x / ay) / 2;
        v = d.y > 0 ? (1 + d.z / ay) / 2 : (1 - d.z / ay) / 2;
    } else {
        face = faceOf[2][d.z < 0];
        u = (1 + d.x / az) / 2;
        v = d.z > 0 ? (1 - d.y / az) / 2 : (1 + d.y / az) / 2;
    }
    return readTexture(faceAddress(face), u, v);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const int x0 = std::min(std::max((int)(u * m_FaceWidth), 0), m_FaceWidth - 1);
    const int y0 = std::min(std::max((int)(v * m_FaceHeight), 0), m_FaceHeight - 1);
    const float* t = addr + 3 * (y0 * m_FaceWidth + x0);
    return Color(t[0], t[1], t[2]);
}
