// The handout's bilinear at (u, 1 - v), in float: v taken to run from the
// top of the image down. fetchColor is right.
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
    const float px = (float)u * W, py = (1.0f - (float)v) * H;   // images start at the top
    const int x0 = std::clamp((int)px, 0, W - 1), y0 = std::clamp((int)py, 0, H - 1);
    const int x1 = std::min(x0 + 1, W - 1), y1 = std::min(y0 + 1, H - 1);
    const float a = px - (int)px, b = py - (int)py;
    float rgb[3];
    for (int c = 0; c < 3; ++c) {
        const float c0 = (1 - a) * addr[3 * (y0 * W + x0) + c] + a * addr[3 * (y0 * W + x1) + c];
        const float c1 = (1 - a) * addr[3 * (y1 * W + x0) + c] + a * addr[3 * (y1 * W + x1) + c];
        rgb[c] = (1 - b) * c0 + b * c1;
    }
    return Color(rgb[0], rgb[1], rgb[2]);
}
// readTexture:end
