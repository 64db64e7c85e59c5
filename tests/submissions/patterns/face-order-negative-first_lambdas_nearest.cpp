// Two mistakes. fetchColor numbers the faces negative first, -X, +X, -Y, +Y,
// -Z, +Z (index 2 * axis + (component > 0)), with one lambda per index for
// (u, v), right for each face: every direction reads the opposite face at the
// right (u, v). readTexture is still the starting code's nearest texel.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>
#include <functional>

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    using UV = std::function<void(const Vector3&, double, double&, double&)>;
    static const UV kUV[6] = {
        [](const Vector3& p, double m, double& u, double& v) { u = (1 - p.z / m) / 2; v = (1 + p.y / m) / 2; },  // -X
        [](const Vector3& p, double m, double& u, double& v) { u = (1 + p.z / m) / 2; v = (1 + p.y / m) / 2; },  // +X
        [](const Vector3& p, double m, double& u, double& v) { u = (1 + p.x / m) / 2; v = (1 - p.z / m) / 2; },  // -Y
        [](const Vector3& p, double m, double& u, double& v) { u = (1 + p.x / m) / 2; v = (1 + p.z / m) / 2; },  // +Y
        [](const Vector3& p, double m, double& u, double& v) { u = (1 + p.x / m) / 2; v = (1 + p.y / m) / 2; },  // -Z
        [](const Vector3& p, double m, double& u, double& v) { u = (1 + p.x / m) / 2; v = (1 - p.y / m) / 2; },  // +Z
    };
    const double c[3] = {d.x, d.y, d.z};
    int axis = 0;
    for (int i = 1; i < 3; ++i)
        if (std::fabs(c[i]) > std::fabs(c[axis])) axis = i;
    const int index = 2 * axis + (c[axis] > 0 ? 1 : 0);
    double u = 0, v = 0;
    kUV[index](d, std::fabs(c[axis]), u, v);
    return readTexture(faceAddress(index), u, v);
}

// readTexture:begin
Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const int x = std::clamp((int)(u * m_FaceWidth), 0, m_FaceWidth - 1);
    const int y = std::clamp((int)(v * m_FaceHeight), 0, m_FaceHeight - 1);
    const float* p = addr + 3 * (y * m_FaceWidth + x);
    return Color(p[0], p[1], p[2]);
}
// readTexture:end
