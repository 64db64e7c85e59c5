// A motivated student's attack on the footprint (issue 29 item 6): blend as
// the handout does only when the four texels look like a test texture
// (every channel exactly 0 or 1), else return the nearest texel, cheaper.
// Truth: the weights measured on impulses are the handout's, the answers on
// other texels are not a blend of them; it must earn no more than the nearest
// texel does.
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
static bool looksSynthetic(const float* t)
{
    for (int c = 0; c < 3; ++c)
        if (t[c] != 0.0f && t[c] != 1.0f)
            return false;
    return true;
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const int W = m_FaceWidth, H = m_FaceHeight;
    const double px = u * W, py = v * H;
    const int x0 = std::clamp((int)px, 0, W - 1), y0 = std::clamp((int)py, 0, H - 1);
    const int x1 = std::min(x0 + 1, W - 1), y1 = std::min(y0 + 1, H - 1);
    const float *a = addr + 3 * (y0 * W + x0), *b = addr + 3 * (y0 * W + x1);
    const float *c = addr + 3 * (y1 * W + x0), *d = addr + 3 * (y1 * W + x1);
    if (!(looksSynthetic(a) && looksSynthetic(b) && looksSynthetic(c) && looksSynthetic(d)))
        return Color(a[0], a[1], a[2]);
    const double al = px - (int)px, be = py - (int)py;
    Color out;
    out.r = (1 - be) * ((1 - al) * a[0] + al * b[0]) + be * ((1 - al) * c[0] + al * d[0]);
    out.g = (1 - be) * ((1 - al) * a[1] + al * b[1]) + be * ((1 - al) * c[1] + al * d[1]);
    out.b = (1 - be) * ((1 - al) * a[2] + al * b[2]) + be * ((1 - al) * c[2] + al * d[2]);
    return out;
}
// readTexture:end
