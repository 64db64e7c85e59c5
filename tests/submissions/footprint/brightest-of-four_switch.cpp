// The brightest of the four texels around p (by their sum), not a blend:
// no weights at all. fetchColor is right.
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
    const int x0 = std::clamp((int)(u * W), 0, W - 1), y0 = std::clamp((int)(v * H), 0, H - 1);
    const int xs[2] = {x0, std::min(x0 + 1, W - 1)}, ys[2] = {y0, std::min(y0 + 1, H - 1)};
    Color best;
    double bestSum = -1;
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) {
            const float* t = addr + 3 * (ys[j] * W + xs[i]);
            if (t[0] + t[1] + t[2] > bestSum) {
                bestSum = t[0] + t[1] + t[2];
                best = Color(t[0], t[1], t[2]);
            }
        }
    return best;
}
// readTexture:end
