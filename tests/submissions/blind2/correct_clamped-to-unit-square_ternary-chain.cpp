// TRUTH (written before any grading; checked against tests/helpers/assignment_model.py
// by tests/submissions/blind2/truth/check_truth.py):
//   RIGHT. 100/100 expected; no check should lose a point; no diagnosis id (in particular
//   NOT uv-clamped-inward or coordinate-wraps).
//   Style: fetchColor picks face, major component and the table's (s, t) in one chain of
//   conditional expressions (x before y before z at ties), then CLAMPS u and v to [0, 1]
//   ("just in case"), which never changes them: |s| <= m, so (1 + s/m)/2 is already in
//   [0, 1]. readTexture also clamps u and v to [0, 1] first (a no-op for its inputs in
//   [0, 1]), then the handout's floor, clamp and equations (1)-(3).
//   Zero, NaN and infinite directions return black.
//   What a student must change: nothing.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

namespace {
inline double unit(double q) { return q >= 0.0 ? (q <= 1.0 ? q : 1.0) : 0.0; }   // NaN -> 0
}

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    if (!(std::isfinite(d.x) && std::isfinite(d.y) && std::isfinite(d.z)))
        return Color(0, 0, 0);
    const double ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
    const bool onX = ax >= ay && ax >= az;
    const bool onY = !onX && ay >= az;
    const double m = onX ? ax : (onY ? ay : az);
    if (m == 0.0)
        return Color(0, 0, 0);
    const int face = onX ? (d.x > 0 ? FACE_POS_X : FACE_NEG_X)
                   : onY ? (d.y > 0 ? FACE_POS_Y : FACE_NEG_Y)
                         : (d.z > 0 ? FACE_POS_Z : FACE_NEG_Z);
    const double s = face == FACE_POS_X ? d.z : face == FACE_NEG_X ? -d.z : d.x;
    const double t = face == FACE_POS_X || face == FACE_NEG_X ? d.y
                   : face == FACE_POS_Y ? d.z
                   : face == FACE_NEG_Y ? -d.z
                   : face == FACE_POS_Z ? -d.y
                                        : d.y;
    const double u = unit((1 + s / m) / 2);
    const double v = unit((1 + t / m) / 2);
    return readTexture(faceAddress(face), u, v);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    u = unit(u);
    v = unit(v);
    const double px = u * m_FaceWidth, py = v * m_FaceHeight;
    const int x0 = std::min((int)px, m_FaceWidth - 1), y0 = std::min((int)py, m_FaceHeight - 1);
    const int x1 = std::min(x0 + 1, m_FaceWidth - 1), y1 = std::min(y0 + 1, m_FaceHeight - 1);
    const double alpha = px - (int)px, beta = py - (int)py;
    const float* c00 = addr + 3 * (y0 * m_FaceWidth + x0);
    const float* c10 = addr + 3 * (y0 * m_FaceWidth + x1);
    const float* c01 = addr + 3 * (y1 * m_FaceWidth + x0);
    const float* c11 = addr + 3 * (y1 * m_FaceWidth + x1);
    const Color c0 = Color(c00[0], c00[1], c00[2]) * (1 - alpha) + Color(c10[0], c10[1], c10[2]) * alpha;
    const Color c1 = Color(c01[0], c01[1], c01[2]) * (1 - alpha) + Color(c11[0], c11[1], c11[2]) * alpha;
    return c0 * (1 - beta) + c1 * beta;
}
