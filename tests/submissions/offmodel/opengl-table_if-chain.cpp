// An if-chain with OpenGL's cube-map table (sc, tc, ma from the GL spec):
// +X (sc = -z, tc = -y), -X (sc = +z, tc = -y), +Y (+x, +z), -Y (+x, -z),
// +Z (+x, -y), -Z (sc = -x, tc = -y). Against this assignment's table, +X,
// -X and -Z are turned 180 degrees (u and v both run the wrong way); +Y, -Y
// and +Z agree. readTexture is correct.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    double sc, tc, ma;
    int face;
    const double ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
    if (ax >= ay && ax >= az && d.x > 0) { face = FACE_POS_X; sc = -d.z; tc = -d.y; ma = ax; }
    else if (ax >= ay && ax >= az)       { face = FACE_NEG_X; sc = d.z;  tc = -d.y; ma = ax; }
    else if (ay >= az && d.y > 0)        { face = FACE_POS_Y; sc = d.x;  tc = d.z;  ma = ay; }
    else if (ay >= az)                   { face = FACE_NEG_Y; sc = d.x;  tc = -d.z; ma = ay; }
    else if (d.z > 0)                    { face = FACE_POS_Z; sc = d.x;  tc = -d.y; ma = az; }
    else                                 { face = FACE_NEG_Z; sc = -d.x; tc = -d.y; ma = az; }
    return readTexture(faceAddress(face), (sc / ma + 1.0) / 2.0, (tc / ma + 1.0) / 2.0);
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
