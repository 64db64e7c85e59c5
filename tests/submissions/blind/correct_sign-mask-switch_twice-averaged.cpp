// TRUTH (written before any grading; checked against tests/helpers/assignment_model.py
// by tests/submissions/blind/check_truth.py):
//   RIGHT. 100/100 expected; no check should lose a point; no diagnosis id.
//   Style: the major axis and its sign packed into a 3-bit code, (axis << 1) | negative,
//   and a switch on that code; readTexture is the handout's, written with a lerp template.
//   fetchColor asks readTexture TWICE with the same face and (u, v) and returns the mean of
//   the two answers (a student "averaging for safety"): the mean of two equal colours is
//   that colour, so every answer is the handout's. Ties go to x before y before z (a face
//   the direction touches). Zero, NaN and infinite directions return black.
//   What a student must change: nothing (the second call only costs time).
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

namespace {

template <typename T>
T lerp(const T& a, const T& b, double t) { return a * (1.0 - t) + b * t; }

enum : unsigned {
    PX = (0u << 1) | 0u, NX = (0u << 1) | 1u,
    PY = (1u << 1) | 0u, NY = (1u << 1) | 1u,
    PZ = (2u << 1) | 0u, NZ = (2u << 1) | 1u,
};

} // namespace

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    const double x = direction.x, y = direction.y, z = direction.z;
    const double ax = std::fabs(x), ay = std::fabs(y), az = std::fabs(z);
    unsigned axis = (ax >= ay && ax >= az) ? 0u : (ay >= az ? 1u : 2u);
    const double c = axis == 0 ? x : (axis == 1 ? y : z);
    const double m = std::fabs(c);
    if (!(m > 0.0) || !std::isfinite(m) || std::isnan(x + y + z))
        return Color();
    const unsigned code = (axis << 1) | (std::signbit(c) ? 1u : 0u);

    int face = 0;
    double s = 0.0, t = 0.0;
    switch (code) {
    case PX: face = FACE_POS_X; s = z;  t = y;  break;
    case NX: face = FACE_NEG_X; s = -z; t = y;  break;
    case PY: face = FACE_POS_Y; s = x;  t = z;  break;
    case NY: face = FACE_NEG_Y; s = x;  t = -z; break;
    case PZ: face = FACE_POS_Z; s = x;  t = -y; break;
    case NZ: face = FACE_NEG_Z; s = x;  t = y;  break;
    default: return Color();
    }
    const double u = (1.0 + s / m) / 2.0;
    const double v = (1.0 + t / m) / 2.0;

    const Color first = readTexture(faceAddress(face), u, v);
    const Color second = readTexture(faceAddress(face), u, v);
    return (first + second) * 0.5;
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const int W = m_FaceWidth, H = m_FaceHeight;
    const double px = u * W, py = v * H;
    const double fx = std::floor(px), fy = std::floor(py);
    const int x0 = std::clamp((int)fx, 0, W - 1), x1 = std::clamp((int)fx + 1, 0, W - 1);
    const int y0 = std::clamp((int)fy, 0, H - 1), y1 = std::clamp((int)fy + 1, 0, H - 1);
    const double alpha = px - fx, beta = py - fy;
    auto texel = [&](int tx, int ty) {
        const float* p = addr + 3 * (ty * W + tx);
        return Color(p[0], p[1], p[2]);
    };
    const Color c0 = lerp(texel(x0, y0), texel(x1, y0), alpha);
    const Color c1 = lerp(texel(x0, y1), texel(x1, y1), alpha);
    return lerp(c0, c1, beta);
}
