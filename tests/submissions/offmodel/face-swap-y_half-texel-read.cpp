// Two mistakes at once: fetchColor sends +Y directions to the -Y face and -Y
// to +Y (the faces' indices swapped in its table), and readTexture samples
// half a texel off (p = (uW - 0.5, vH - 0.5), clamped like the handout's).
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    static const int kFace[3][2] = {{FACE_POS_X, FACE_NEG_X}, {FACE_NEG_Y, FACE_POS_Y}, {FACE_POS_Z, FACE_NEG_Z}};
    const double ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
    double u, v;
    int axis;
    if (ax >= ay && ax >= az) { axis = 0; u = (1 + (d.x > 0 ? d.z : -d.z) / ax) / 2; v = (1 + d.y / ax) / 2; }
    else if (ay >= az)        { axis = 1; u = (1 + d.x / ay) / 2; v = (1 + (d.y > 0 ? d.z : -d.z) / ay) / 2; }
    else                      { axis = 2; u = (1 + d.x / az) / 2; v = (1 + (d.z > 0 ? -d.y : d.y) / az) / 2; }
    const double c = axis == 0 ? d.x : axis == 1 ? d.y : d.z;
    return readTexture(faceAddress(kFace[axis][c < 0]), u, v);
}

// readTexture:begin
Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const double px = u * m_FaceWidth - 0.5, py = v * m_FaceHeight - 0.5;
    const int fx = (int)std::floor(px), fy = (int)std::floor(py);
    const double a = px - fx, b = py - fy;
    auto at = [&](int x, int y) {
        x = std::clamp(x, 0, m_FaceWidth - 1);
        y = std::clamp(y, 0, m_FaceHeight - 1);
        const float* p = addr + 3 * (y * m_FaceWidth + x);
        return Color(p[0], p[1], p[2]);
    };
    return (1 - b) * ((1 - a) * at(fx, fy) + a * at(fx + 1, fy)) + b * ((1 - a) * at(fx, fy + 1) + a * at(fx + 1, fy + 1));
}
// readTexture:end
