// Two mistakes. fetchColor, a switch on the face number, turns +X and +Z by
// 180 degrees (u = 1 - s and v = 1 - t of the table's (s, t)); the other
// four faces are right. readTexture samples half a texel off
// (p = (uW - 0.5, vH - 0.5)), clamped.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    const double a[3] = {std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)};
    const int axis = (a[0] >= a[1] && a[0] >= a[2]) ? 0 : (a[1] >= a[2] ? 1 : 2);
    const double c = axis == 0 ? d.x : (axis == 1 ? d.y : d.z);
    const int face = 2 * axis + (c < 0 ? 1 : 0);
    const double m = a[axis];
    double s = 0.5, t = 0.5;
    switch (face) {
    case FACE_POS_X: s = 1 - (1 + d.z / m) / 2; t = 1 - (1 + d.y / m) / 2; break;   // turned 180
    case FACE_NEG_X: s = (1 - d.z / m) / 2;     t = (1 + d.y / m) / 2;     break;
    case FACE_POS_Y: s = (1 + d.x / m) / 2;     t = (1 + d.z / m) / 2;     break;
    case FACE_NEG_Y: s = (1 + d.x / m) / 2;     t = (1 - d.z / m) / 2;     break;
    case FACE_POS_Z: s = 1 - (1 + d.x / m) / 2; t = 1 - (1 - d.y / m) / 2; break;   // turned 180
    case FACE_NEG_Z: s = (1 + d.x / m) / 2;     t = (1 + d.y / m) / 2;     break;
    }
    return readTexture(faceAddress(face), s, t);
}

// readTexture:begin
Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const double px = u * m_FaceWidth - 0.5, py = v * m_FaceHeight - 0.5;
    const int fx = (int)std::floor(px), fy = (int)std::floor(py);
    const double alpha = px - fx, beta = py - fy;
    const int x0 = std::clamp(fx, 0, m_FaceWidth - 1), x1 = std::clamp(fx + 1, 0, m_FaceWidth - 1);
    const int y0 = std::clamp(fy, 0, m_FaceHeight - 1), y1 = std::clamp(fy + 1, 0, m_FaceHeight - 1);
    double out[3];
    for (int k = 0; k < 3; ++k) {
        const double c0 = (1 - alpha) * addr[3 * (y0 * m_FaceWidth + x0) + k] + alpha * addr[3 * (y0 * m_FaceWidth + x1) + k];
        const double c1 = (1 - alpha) * addr[3 * (y1 * m_FaceWidth + x0) + k] + alpha * addr[3 * (y1 * m_FaceWidth + x1) + k];
        out[k] = (1 - beta) * c0 + beta * c1;
    }
    return Color(out[0], out[1], out[2]);
}
// readTexture:end
