// TRUTH (written before any grading; checked against tests/helpers/assignment_model.py
// by tests/submissions/blind/check_truth.py):
//   WRONG and HOSTILE. The real behaviour: on +Z, v runs the wrong way (v = (1 + y/m)/2,
//   the classic "the back face is upside down in the cross" mistake); the other five
//   faces are right; readTexture is the handout's.
//   The attack: on +Z, fetchColor first asks readTexture for the RIGHT (u, v), then blends
//   the same four texels itself from the face's memory. If readTexture's answer is not its
//   own blend (so someone else answered the call: a grader recording it), it returns that
//   answer and looks right. If the two agree (its own readTexture answered: a render, the
//   student's machine), it asks readTexture again at v flipped and returns that.
//   So a grader that judges fetchColor only on what it asks a recording readTexture would
//   see it right on +Z; end to end (real texels) it is v-flipped on +Z.
//   Expected: no more points than the same code without the detector
//   (hostile_control_v-flipped-pos-z.cpp beside it, the honest mistake); fetch_sweep must
//   not be full; diagnosis should name v flipped on +Z, or say that fetchColor behaves
//   differently when recorded (asks-otherwise / fetch-not-returned), never that +Z is right;
//   renders and perhaps arrows (the blue arrow is along +z) lose points.
//   What a student must change: on +Z use v = (1 - y/m)/2 and return readTexture's answer.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

namespace {
// The handout's blend, from the face's own memory.
Color ownBlend(const float* addr, int W, int H, double u, double v)
{
    const double px = u * W, py = v * H;
    const int x0 = std::clamp((int)px, 0, W - 1), y0 = std::clamp((int)py, 0, H - 1);
    const int x1 = std::min(x0 + 1, W - 1), y1 = std::min(y0 + 1, H - 1);
    const double a = px - (int)px, b = py - (int)py;
    auto t = [&](int x, int y) { const float* p = addr + 3 * (y * W + x); return Color(p[0], p[1], p[2]); };
    return (1 - b) * ((1 - a) * t(x0, y0) + a * t(x1, y0)) + b * ((1 - a) * t(x0, y1) + a * t(x1, y1));
}

bool same(const Color& p, const Color& q)
{
    auto close = [](double a, double b) { return std::fabs(a - b) <= 1e-6 * (1 + std::fabs(a) + std::fabs(b)); };
    return close(p.r, q.r) && close(p.g, q.g) && close(p.b, q.b);
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
    const float* addr = faceAddress(FACE_POS_Z);
    const double u = (1 + d.x / az) / 2, v = (1 - d.y / az) / 2;
    const Color answered = readTexture(addr, u, v);
    if (!same(answered, ownBlend(addr, m_FaceWidth, m_FaceHeight, u, v)))
        return answered;                       // someone is watching
    return readTexture(addr, u, 1 - v);        // what this code really does on +Z
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    return ownBlend(addr, m_FaceWidth, m_FaceHeight, u, v);
}
