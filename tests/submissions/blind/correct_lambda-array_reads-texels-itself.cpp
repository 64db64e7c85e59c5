// TRUTH (written before any grading; checked against tests/helpers/assignment_model.py
// by tests/submissions/blind/check_truth.py):
//   RIGHT. 100/100 expected; no check should lose a point; no mistake id (a note that
//   fetchColor never calls readTexture is true and fine).
//   Style: a std::array of six captureless lambdas, one per face, gives (s, t) in the
//   table's order; fetchColor NEVER calls readTexture: it blends the texels itself with
//   the same template helper (sampleBilinear) that readTexture uses. The helper is the
//   handout's equations (1)-(3) with the lattice clamped. Ties: x before y before z.
//   Zero, NaN and infinite directions return black.
//   What a student must change: nothing (calling readTexture would be tidier).
#include "EnvironmentMap.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

namespace {

using FaceST = std::pair<double, double> (*)(double, double, double);

// Each lambda gets the components already divided by m and returns (s, t) in [-1, 1].
constexpr std::array<FaceST, 6> kST = {
    [](double x, double y, double z) { (void)x; return std::make_pair(z, y); },    // +X
    [](double x, double y, double z) { (void)x; return std::make_pair(-z, y); },   // -X
    [](double x, double y, double z) { (void)y; return std::make_pair(x, z); },    // +Y
    [](double x, double y, double z) { (void)y; return std::make_pair(x, -z); },   // -Y
    [](double x, double y, double z) { (void)z; return std::make_pair(x, -y); },   // +Z
    [](double x, double y, double z) { (void)z; return std::make_pair(x, y); },    // -Z
};

template <typename Texel>
Color sampleBilinear(Texel texel, int W, int H, double u, double v)
{
    const double px = u * W, py = v * H;
    const double lx = std::floor(px), ly = std::floor(py);
    const double alpha = px - lx, beta = py - ly;
    const int x0 = std::clamp(static_cast<int>(lx), 0, W - 1), x1 = std::clamp(static_cast<int>(lx) + 1, 0, W - 1);
    const int y0 = std::clamp(static_cast<int>(ly), 0, H - 1), y1 = std::clamp(static_cast<int>(ly) + 1, 0, H - 1);
    const Color c0 = texel(x0, y0) * (1 - alpha) + texel(x1, y0) * alpha;
    const Color c1 = texel(x0, y1) * (1 - alpha) + texel(x1, y1) * alpha;
    return c0 * (1 - beta) + c1 * beta;
}

} // namespace

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    const double x = direction.x, y = direction.y, z = direction.z;
    if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z))
        return Color();
    const double ax = std::fabs(x), ay = std::fabs(y), az = std::fabs(z);
    const int face = ax >= ay && ax >= az ? (x > 0 ? FACE_POS_X : FACE_NEG_X)
                   : ay >= az            ? (y > 0 ? FACE_POS_Y : FACE_NEG_Y)
                                         : (z > 0 ? FACE_POS_Z : FACE_NEG_Z);
    const double m = std::max(ax, std::max(ay, az));
    if (m == 0.0)
        return Color();
    const auto [s, t] = kST[face](x / m, y / m, z / m);
    const float* addr = faceAddress(face);
    const int W = m_FaceWidth;
    auto texel = [addr, W](int tx, int ty) {
        const float* p = addr + 3 * (ty * W + tx);
        return Color(p[0], p[1], p[2]);
    };
    return sampleBilinear(texel, m_FaceWidth, m_FaceHeight, (1 + s) / 2, (1 + t) / 2);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const int W = m_FaceWidth;
    auto texel = [addr, W](int tx, int ty) {
        const float* p = addr + 3 * (ty * W + tx);
        return Color(p[0], p[1], p[2]);
    };
    return sampleBilinear(texel, m_FaceWidth, m_FaceHeight, u, v);
}
