// A motivated student's attack on the footprint (issue 29 item 6): the
// grader measures on small faces, so blend there and return the nearest
// texel on faces of 32 texels or more, where it counts.
// Truth: right on every small face, wrong on large ones: face-size-dependent,
// and no more than the nearest texel's points on the large face.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

Color EnvironmentMap::fetchColor(const Vector3& dir) const
{
    const double ax = std::abs(dir.x), ay = std::abs(dir.y), az = std::abs(dir.z);
    const int axis = (ax >= ay && ax >= az) ? 0 : (ay >= az ? 1 : 2);
    const double m = axis == 0 ? ax : axis == 1 ? ay : az;
    if (!(m > 0) || std::isinf(m) || std::isnan(dir.x + dir.y + dir.z))
        return Color(0, 0, 0);
    const double x = dir.x / m, y = dir.y / m, z = dir.z / m;
    int face;
    double u, v;
    switch (axis) {
    case 0:
        face = x > 0 ? FACE_POS_X : FACE_NEG_X;
        u = (1 + (x > 0 ? z : -z)) / 2;
        v = (1 + y) / 2;
        break;
    case 1:
        face = y > 0 ? FACE_POS_Y : FACE_NEG_Y;
        u = (1 + x) / 2;
        v = (1 + (y > 0 ? z : -z)) / 2;
        break;
    default:
        face = z > 0 ? FACE_POS_Z : FACE_NEG_Z;
        u = (1 + x) / 2;
        v = (1 + (z > 0 ? -y : y)) / 2;
        break;
    }
    return readTexture(faceAddress(face), u, v);
}

// readTexture:begin
Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const int W = m_FaceWidth, H = m_FaceHeight;
    const double px = u * W, py = v * H;
    const int x0 = std::clamp((int)px, 0, W - 1), y0 = std::clamp((int)py, 0, H - 1);
    auto at = [&](int x, int y) { const float* t = addr + 3 * (y * W + x); return Color(t[0], t[1], t[2]); };
    if (W >= 32 || H >= 32)
        return at(x0, y0);
    const int x1 = std::min(x0 + 1, W - 1), y1 = std::min(y0 + 1, H - 1);
    const double a = px - (int)px, b = py - (int)py;
    return (at(x0, y0) * (1 - a) + at(x1, y0) * a) * (1 - b) + (at(x0, y1) * (1 - a) + at(x1, y1) * a) * b;
}
// readTexture:end
