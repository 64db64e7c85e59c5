// TRUTH (written before any grading; checked against tests/helpers/assignment_model.py
// by tests/submissions/blind2/truth/check_truth.py):
//   WRONG, in readTexture only. fetchColor is right (face from a switch on an enum of the
//   major axis, x before y before z at ties; zero, NaN and infinite directions return black).
//   readTexture takes the right lattice points (floor, clamped x0, x1 = x0 + 1, y0, y1) and
//   the right alpha = frac(uW), beta = frac(vH), with c00 = (x0, y0), c10 = (x1, y0),
//   c01 = (x0, y1), c11 = (x1, y1) as the handout names them, but blends them with a
//   lerp<T>(a, b, t) = (1 - t) a + t b helper in the wrong order of fractions:
//       c0 = lerp(c00, c10, beta); c1 = lerp(c01, c11, beta); c = lerp(c0, c1, alpha)
//   i.e. c = (1-a)(1-b) c00 + (1-a) b c10 + a (1-b) c01 + a b c11: the columns pair
//   is weighed by beta and the rows by alpha; equivalently the handout's blend with c10
//   and c01 exchanged. Right where alpha = beta, where c10 = c01, and where x1 = x0 and
//   y1 = y0 (the top-right texel); wrong elsewhere.
//   Expected: read_texture loses points; fetch_sweep and arrows keep full points; renders
//   and stability may lose a little; speed keeps. Diagnosis: fractions-exchanged (not
//   weights-swapped, texel-index-transposed or width-height-swapped; no fetchColor id).
//   What a student must change: c0 = lerp(c00, c10, alpha), c1 = lerp(c01, c11, alpha),
//   c = lerp(c0, c1, beta).
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

namespace {

enum class Axis { X, Y, Z };

template <typename T>
T lerp(T a, T b, double t)
{
    return a * (1.0 - t) + b * t;
}

Color texel(const float* addr, int width, int x, int y)
{
    const float* p = addr + 3 * (y * width + x);
    return Color(p[0], p[1], p[2]);
}

}  // namespace

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    const double ax = std::fabs(direction.x), ay = std::fabs(direction.y), az = std::fabs(direction.z);
    if (!(std::isfinite(ax) && std::isfinite(ay) && std::isfinite(az)) || (ax == 0 && ay == 0 && az == 0))
        return Color(0, 0, 0);
    Axis axis = Axis::Z;
    if (ax >= ay && ax >= az)
        axis = Axis::X;
    else if (ay >= az)
        axis = Axis::Y;

    switch (axis) {
    case Axis::X: {
        const double m = ax;
        if (direction.x > 0)
            return readTexture(faceAddress(FACE_POS_X), (1 + direction.z / m) / 2, (1 + direction.y / m) / 2);
        return readTexture(faceAddress(FACE_NEG_X), (1 - direction.z / m) / 2, (1 + direction.y / m) / 2);
    }
    case Axis::Y: {
        const double m = ay;
        if (direction.y > 0)
            return readTexture(faceAddress(FACE_POS_Y), (1 + direction.x / m) / 2, (1 + direction.z / m) / 2);
        return readTexture(faceAddress(FACE_NEG_Y), (1 + direction.x / m) / 2, (1 - direction.z / m) / 2);
    }
    case Axis::Z:
    default: {
        const double m = az;
        if (direction.z > 0)
            return readTexture(faceAddress(FACE_POS_Z), (1 + direction.x / m) / 2, (1 - direction.y / m) / 2);
        return readTexture(faceAddress(FACE_NEG_Z), (1 + direction.x / m) / 2, (1 + direction.y / m) / 2);
    }
    }
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const double px = u * m_FaceWidth;
    const double py = v * m_FaceHeight;
    const double fx = std::floor(px), fy = std::floor(py);
    const double alpha = px - fx;
    const double beta = py - fy;
    const int x0 = std::clamp((int)fx, 0, m_FaceWidth - 1);
    const int x1 = std::clamp((int)fx + 1, 0, m_FaceWidth - 1);
    const int y0 = std::clamp((int)fy, 0, m_FaceHeight - 1);
    const int y1 = std::clamp((int)fy + 1, 0, m_FaceHeight - 1);

    const Color c00 = texel(addr, m_FaceWidth, x0, y0);
    const Color c10 = texel(addr, m_FaceWidth, x1, y0);
    const Color c01 = texel(addr, m_FaceWidth, x0, y1);
    const Color c11 = texel(addr, m_FaceWidth, x1, y1);

    // blend down each pair, then across
    const Color c0 = lerp(c00, c10, beta);
    const Color c1 = lerp(c01, c11, beta);
    return lerp(c0, c1, alpha);
}
