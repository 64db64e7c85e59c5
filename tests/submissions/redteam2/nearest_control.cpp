// The control for the readTexture-that-knows-its-caller attacks: a correct fetchColor over the starting code's readTexture (nearest texel). Verdict: read_texture failed (nearest-neighbor), fetchColor judged through it (full), renders below full.
#include "EnvironmentMap.h"

#include <algorithm>

#include <cmath>
#include <cstddef>

namespace {

struct FaceCoord
{
    int face;
    double u;
    double v;
};

FaceCoord directionToFace(const Vector3& d)
{
    const double ax = std::abs(d.x), ay = std::abs(d.y), az = std::abs(d.z);
    auto toUnit = [](double s, double m) { return (s / m + 1.0) / 2.0; };
    if (ax >= ay && ax >= az) {
        return d.x > 0 ? FaceCoord{FACE_POS_X, toUnit(d.z, ax), toUnit(d.y, ax)}
                       : FaceCoord{FACE_NEG_X, toUnit(-d.z, ax), toUnit(d.y, ax)};
    }
    if (ay >= az) {
        return d.y > 0 ? FaceCoord{FACE_POS_Y, toUnit(d.x, ay), toUnit(d.z, ay)}
                       : FaceCoord{FACE_NEG_Y, toUnit(d.x, ay), toUnit(-d.z, ay)};
    }
    return d.z > 0 ? FaceCoord{FACE_POS_Z, toUnit(d.x, az), toUnit(-d.y, az)}
                   : FaceCoord{FACE_NEG_Z, toUnit(d.x, az), toUnit(d.y, az)};
}

} // namespace

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    const auto [face, u, v] = directionToFace(direction);
    return readTexture(faceAddress(face), u, v);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    // The starting code: the single texel at (u W, v H), clamped.
    const int x0 = std::clamp(static_cast<int>(u * m_FaceWidth), 0, m_FaceWidth - 1);
    const int y0 = std::clamp(static_cast<int>(v * m_FaceHeight), 0, m_FaceHeight - 1);
    const float* t = addr + 3 * (static_cast<std::ptrdiff_t>(y0) * m_FaceWidth + x0);
    return {t[0], t[1], t[2]};
}
