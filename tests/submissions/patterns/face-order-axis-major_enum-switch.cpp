// The student numbers the faces axis by axis, +X, +Y, +Z, -X, -Y, -Z (an enum
// class in that order), and passes the enum's value to faceAddress, which
// takes the handout's order +X, -X, +Y, -Y, +Z, -Z. (u, v) are right for the
// face the direction exits through. So +X and -Z are right, and -X reads
// the -Y face, +Y reads -X, -Y reads +Z, +Z reads +Y, each at the right
// (u, v). readTexture is the handout's.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

namespace {
enum class Face { PosX, PosY, PosZ, NegX, NegY, NegZ };
}

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    const double ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
    Face face;
    if (ax >= ay && ax >= az) face = d.x > 0 ? Face::PosX : Face::NegX;
    else if (ay >= az)        face = d.y > 0 ? Face::PosY : Face::NegY;
    else                      face = d.z > 0 ? Face::PosZ : Face::NegZ;
    double s = 0, t = 0, m = 1;
    switch (face) {
    case Face::PosX: m = ax; s =  d.z; t =  d.y; break;
    case Face::NegX: m = ax; s = -d.z; t =  d.y; break;
    case Face::PosY: m = ay; s =  d.x; t =  d.z; break;
    case Face::NegY: m = ay; s =  d.x; t = -d.z; break;
    case Face::PosZ: m = az; s =  d.x; t = -d.y; break;
    case Face::NegZ: m = az; s =  d.x; t =  d.y; break;
    }
    return readTexture(faceAddress(static_cast<int>(face)), 0.5 * (1 + s / m), 0.5 * (1 + t / m));
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
