// Correct: the handout's lookup, but fetchColor keeps readTexture's answer in three floats ("like the texels") before returning it, a round trip of the colour through float and nothing else (a blind reviewer, 2026-12-07: it lost speed's 5 points while the shim counted only a bit-for-bit answer as returned). Verdict: 100, no diagnosis.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

using std::max;
using std::min;

Color EnvironmentMap::fetchColor(const Vector3& dir) const
{
    const double ax = std::fabs(dir.x), ay = std::fabs(dir.y), az = std::fabs(dir.z);
    int face; double u, v;
    if (ax >= ay && ax >= az) {
        face = dir.x > 0 ? FACE_POS_X : FACE_NEG_X;
        u = dir.x > 0 ? (1 + dir.z / ax) / 2 : (1 - dir.z / ax) / 2;
        v = (1 + dir.y / ax) / 2;
    } else if (ay >= az) {
        face = dir.y > 0 ? FACE_POS_Y : FACE_NEG_Y;
        u = (1 + dir.x / ay) / 2;
        v = dir.y > 0 ? (1 + dir.z / ay) / 2 : (1 - dir.z / ay) / 2;
    } else {
        face = dir.z > 0 ? FACE_POS_Z : FACE_NEG_Z;
        u = (1 + dir.x / az) / 2;
        v = dir.z > 0 ? (1 - dir.y / az) / 2 : (1 + dir.y / az) / 2;
    }
    const Color c = readTexture(faceAddress(face), u, v);
    const float r = (float)c.r, g = (float)c.g, b = (float)c.b;
    return Color(r, g, b) * 1.0f;
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const double px = u * m_FaceWidth, py = v * m_FaceHeight;
    const int x0 = (int)std::floor(px), y0 = (int)std::floor(py);
    const double alpha = px - x0, beta = py - y0;
    const int xa = max(0, min(x0, m_FaceWidth - 1)), xb = max(0, min(x0 + 1, m_FaceWidth - 1));
    const int ya = max(0, min(y0, m_FaceHeight - 1)), yb = max(0, min(y0 + 1, m_FaceHeight - 1));
    auto C = [&](int x, int y) { const float* t = addr + 3 * (y * m_FaceWidth + x); return Color(t[0], t[1], t[2]); };
    const Color c0 = (1 - alpha) * C(xa, ya) + alpha * C(xb, ya);
    const Color c1 = (1 - alpha) * C(xa, yb) + alpha * C(xb, yb);
    return (1 - beta) * c0 + beta * c1;
}
