// Pattern 10 (issue 29): fetchColor clamps u and v to [0.001, 0.999] before calling readTexture. Right inside; within 0.001 of a face's border it asks for (u, v) moved inward. readTexture is correct.
#include "EnvironmentMap.h"

#include <cmath>

static int majorFace(double x, double y, double z)
{
    const double ax = std::fabs(x), ay = std::fabs(y), az = std::fabs(z);
    if (ax >= ay && ax >= az)
        return x > 0 ? FACE_POS_X : FACE_NEG_X;
    if (ay >= az)
        return y > 0 ? FACE_POS_Y : FACE_NEG_Y;
    return z > 0 ? FACE_POS_Z : FACE_NEG_Z;
}

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    const double x = direction.x, y = direction.y, z = direction.z;
    const int face = majorFace(x, y, z);
    double m = 0, s = 0, t = 0;
    switch (face) {
    case FACE_POS_X: m = x;  s = z;  t = y;  break;
    case FACE_NEG_X: m = -x; s = -z; t = y;  break;
    case FACE_POS_Y: m = y;  s = x;  t = z;  break;
    case FACE_NEG_Y: m = -y; s = x;  t = -z; break;
    case FACE_POS_Z: m = z;  s = x;  t = -y; break;
    case FACE_NEG_Z: m = -z; s = x;  t = y;  break;
    default: return Color(0, 0, 0);
    }
    const double u = 0.5 * (s / m + 1.0);
    const double v = 0.5 * (t / m + 1.0);
    // the mistake: a margin that the handout does not ask for
    return readTexture(faceAddress(face), std::fmin(std::fmax(u, 0.001), 0.999), std::fmin(std::fmax(v, 0.001), 0.999));
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const double px = u * m_FaceWidth, py = v * m_FaceHeight;
    const double fx = std::floor(px), fy = std::floor(py);
    const double alpha = px - fx, beta = py - fy;
    int xs[2], ys[2];
    for (int k = 0; k < 2; ++k) {
        int x = (int)fx + k, y = (int)fy + k;
        if (x < 0) x = 0;
        if (x > m_FaceWidth - 1) x = m_FaceWidth - 1;
        if (y < 0) y = 0;
        if (y > m_FaceHeight - 1) y = m_FaceHeight - 1;
        xs[k] = x;
        ys[k] = y;
    }
    double out[3];
    for (int ch = 0; ch < 3; ++ch) {
        const double c00 = addr[3 * (ys[0] * m_FaceWidth + xs[0]) + ch];
        const double c10 = addr[3 * (ys[0] * m_FaceWidth + xs[1]) + ch];
        const double c01 = addr[3 * (ys[1] * m_FaceWidth + xs[0]) + ch];
        const double c11 = addr[3 * (ys[1] * m_FaceWidth + xs[1]) + ch];
        const double c0 = (1 - alpha) * c00 + alpha * c10;
        const double c1 = (1 - alpha) * c01 + alpha * c11;
        out[ch] = (1 - beta) * c0 + beta * c1;
    }
    return Color(out[0], out[1], out[2]);
}
