// Compound zoo. fetchColor passes the components to a helper taking float
// arguments: fine for ordinary directions, but tiny components (< 1e-38)
// lose precision or become 0 and huge ones (> 3e38) become infinite.
// readTexture: width and height swapped (p = (uH, vW)), clamped with the right sizes.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

static float faceCoord(float a, float m) { return 0.5f * (1.0f + a / m); }

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    const double ax = std::fabs(direction.x), ay = std::fabs(direction.y), az = std::fabs(direction.z);
    if (ax >= ay && ax >= az) {
        if (direction.x > 0) return readTexture(faceAddress(FACE_POS_X), faceCoord(direction.z, ax), faceCoord(direction.y, ax));
        return readTexture(faceAddress(FACE_NEG_X), faceCoord(-direction.z, ax), faceCoord(direction.y, ax));
    }
    if (ay >= az) {
        if (direction.y > 0) return readTexture(faceAddress(FACE_POS_Y), faceCoord(direction.x, ay), faceCoord(direction.z, ay));
        return readTexture(faceAddress(FACE_NEG_Y), faceCoord(direction.x, ay), faceCoord(-direction.z, ay));
    }
    if (direction.z > 0) return readTexture(faceAddress(FACE_POS_Z), faceCoord(direction.x, az), faceCoord(-direction.y, az));
    return readTexture(faceAddress(FACE_NEG_Z), faceCoord(direction.x, az), faceCoord(direction.y, az));
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const double px = u * m_FaceHeight, py = v * m_FaceWidth;     // swapped sizes
    const int xf = (int)px, yf = (int)py;
    const double a = px - xf, b = py - yf;
    const int x0 = std::min(xf, m_FaceWidth - 1), x1 = std::min(xf + 1, m_FaceWidth - 1);
    const int y0 = std::min(yf, m_FaceHeight - 1), y1 = std::min(yf + 1, m_FaceHeight - 1);
    Color out;
    const int xs[2] = {x0, x1}, ys[2] = {y0, y1};
    const double wx[2] = {1 - a, a}, wy[2] = {1 - b, b};
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) {
            const float* t = addr + 3 * (ys[j] * m_FaceWidth + xs[i]);
            out += Color(t[0], t[1], t[2]) * (wx[i] * wy[j]);
        }
    return out;
}
