// p = (u (W + 1), v (H + 1)), then the handout's clamped bilinear.
// fetchColor is right.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    const double ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
    const double m = std::max(ax, std::max(ay, az));
    if (!(m > 0) || !std::isfinite(m) || std::isnan(d.x + d.y + d.z))
        return Color();                       // no face to read
    const double x = d.x / m, y = d.y / m, z = d.z / m;
    if (ax >= ay && ax >= az) {
        if (x > 0)
            return readTexture(faceAddress(FACE_POS_X), 0.5 * (1 + z), 0.5 * (1 + y));
        return readTexture(faceAddress(FACE_NEG_X), 0.5 * (1 - z), 0.5 * (1 + y));
    }
    if (ay >= az) {
        if (y > 0)
            return readTexture(faceAddress(FACE_POS_Y), 0.5 * (1 + x), 0.5 * (1 + z));
        return readTexture(faceAddress(FACE_NEG_Y), 0.5 * (1 + x), 0.5 * (1 - z));
    }
    if (z > 0)
        return readTexture(faceAddress(FACE_POS_Z), 0.5 * (1 + x), 0.5 * (1 - y));
    return readTexture(faceAddress(FACE_NEG_Z), 0.5 * (1 + x), 0.5 * (1 + y));
}

// readTexture:begin
Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const int W = m_FaceWidth, H = m_FaceHeight;
    const double px = u * (W + 1), py = v * (H + 1);
    const int x0 = (int)px, y0 = (int)py;
    const double alpha = px - x0, beta = py - y0;
    auto texel = [&](int x, int y) {
        x = std::clamp(x, 0, W - 1);
        y = std::clamp(y, 0, H - 1);
        return Color(addr[3 * (y * W + x)], addr[3 * (y * W + x) + 1], addr[3 * (y * W + x) + 2]);
    };
    const Color c0 = texel(x0, y0) * (1 - alpha) + texel(x0 + 1, y0) * alpha;
    const Color c1 = texel(x0, y0 + 1) * (1 - alpha) + texel(x0 + 1, y0 + 1) * alpha;
    return c0 * (1 - beta) + c1 * beta;
}
// readTexture:end
