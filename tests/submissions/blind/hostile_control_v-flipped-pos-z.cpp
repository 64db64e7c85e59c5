// TRUTH (written before any grading; checked by tests/submissions/blind/check_truth.py):
//   WRONG, the CONTROL for hostile_recorded-by-own-blend_v-flipped-pos-z.cpp: the same
//   code without the detector. On +Z, v runs the wrong way (v = (1 + y/m)/2); the other
//   five faces and readTexture (the handout's) are right.
//   Expected: fetch_sweep loses about a sixth of its points; diagnosis v-flipped on +Z only;
//   renders lose some; read_texture keeps 25/25. The hostile file must score no more.
//   What a student must change: on +Z use v = (1 - y/m)/2.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

namespace {
Color ownBlend(const float* addr, int W, int H, double u, double v)
{
    const double px = u * W, py = v * H;
    const int x0 = std::clamp((int)px, 0, W - 1), y0 = std::clamp((int)py, 0, H - 1);
    const int x1 = std::min(x0 + 1, W - 1), y1 = std::min(y0 + 1, H - 1);
    const double a = px - (int)px, b = py - (int)py;
    auto t = [&](int x, int y) { const float* p = addr + 3 * (y * W + x); return Color(p[0], p[1], p[2]); };
    return (1 - b) * ((1 - a) * t(x0, y0) + a * t(x1, y0)) + b * ((1 - a) * t(x0, y1) + a * t(x1, y1));
}
}

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    const double ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
    if (!std::isfinite(ax) || !std::isfinite(ay) || !std::isfinite(az))
        return Color();
    if (ax >= ay && ax >= az && ax > 0)
        return d.x > 0 ? readTexture(faceAddress(FACE_POS_X), (1 + d.z / ax) / 2, (1 + d.y / ax) / 2)
                       : readTexture(faceAddress(FACE_NEG_X), (1 - d.z / ax) / 2, (1 + d.y / ax) / 2);
    if (ay >= az && ay > 0)
        return d.y > 0 ? readTexture(faceAddress(FACE_POS_Y), (1 + d.x / ay) / 2, (1 + d.z / ay) / 2)
                       : readTexture(faceAddress(FACE_NEG_Y), (1 + d.x / ay) / 2, (1 - d.z / ay) / 2);
    if (!(az > 0))
        return Color();
    if (d.z < 0)
        return readTexture(faceAddress(FACE_NEG_Z), (1 + d.x / az) / 2, (1 + d.y / az) / 2);
    return readTexture(faceAddress(FACE_POS_Z), (1 + d.x / az) / 2, (1 + d.y / az) / 2);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    return ownBlend(addr, m_FaceWidth, m_FaceHeight, u, v);
}
