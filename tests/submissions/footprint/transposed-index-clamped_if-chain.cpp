// Issue 29, pattern 9: the handout's bilinear with both lattice points
// clamped, but the texel index transposed: 3 * (x * W + y). On a square face
// that reads texel (y, x); on others it reads other rows, or past the face.
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
    const double px = u * W, py = v * H;
    const int x0 = std::clamp((int)std::floor(px), 0, W - 1), x1 = std::clamp(x0 + 1, 0, W - 1);
    const int y0 = std::clamp((int)std::floor(py), 0, H - 1), y1 = std::clamp(y0 + 1, 0, H - 1);
    const double alpha = px - std::floor(px), beta = py - std::floor(py);
    auto c = [&](int x, int y) {
        const float* t = &addr[3 * (x * W + y)];
        return Color(t[0], t[1], t[2]);
    };
    const Color c0 = c(x0, y0) * (1 - alpha) + c(x1, y0) * alpha;
    const Color c1 = c(x0, y1) * (1 - alpha) + c(x1, y1) * alpha;
    return c0 * (1 - beta) + c1 * beta;
}
// readTexture:end
