// TRUTH (written before any grading; checked against tests/helpers/assignment_model.py
// by tests/submissions/blind/check_truth.py):
//   RIGHT. 100/100 expected; no check should lose a point; no diagnosis id.
//   Style: one 3x3 matrix per face turns the direction into the face's frame
//   (s, t, n) = R d, with u = (1 + s/n)/2, v = (1 + t/n)/2 (the table's rows, written as
//   matrices); the face is the one whose n is the largest, x before y before z at ties.
//   fetchColor MEMOISES the geometry, not the colour: a direct-mapped cache (thread_local,
//   1024 entries, keyed by the direction's exact bits) of (face, u, v). It still calls
//   readTexture on every call, so a new texture or face size is always read afresh.
//   Zero, NaN and infinite directions return black.
//   What a student must change: nothing.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace {

// Rows: s (becomes u), t (becomes v), n (the outward normal of the face).
const double kFrame[6][3][3] = {
    {{0, 0, 1}, {0, 1, 0}, {1, 0, 0}},     // +X: s = z,  t = y,  n = x
    {{0, 0, -1}, {0, 1, 0}, {-1, 0, 0}},   // -X: s = -z, t = y,  n = -x
    {{1, 0, 0}, {0, 0, 1}, {0, 1, 0}},     // +Y: s = x,  t = z,  n = y
    {{1, 0, 0}, {0, 0, -1}, {0, -1, 0}},   // -Y: s = x,  t = -z, n = -y
    {{1, 0, 0}, {0, -1, 0}, {0, 0, 1}},    // +Z: s = x,  t = -y, n = z
    {{1, 0, 0}, {0, 1, 0}, {0, 0, -1}},    // -Z: s = x,  t = y,  n = -z
};

struct Hit { int face; double u, v; };

struct Entry { std::uint64_t key[3]; Hit hit; bool used; };

Hit locate(const double d[3])
{
    const double a[3] = {std::fabs(d[0]), std::fabs(d[1]), std::fabs(d[2])};
    const int axis = (a[0] >= a[1] && a[0] >= a[2]) ? 0 : (a[1] >= a[2] ? 1 : 2);
    const int face = 2 * axis + (d[axis] < 0 ? 1 : 0);
    double l[3];
    for (int r = 0; r < 3; ++r)
        l[r] = kFrame[face][r][0] * d[0] + kFrame[face][r][1] * d[1] + kFrame[face][r][2] * d[2];
    return Hit{face, (1.0 + l[0] / l[2]) / 2.0, (1.0 + l[1] / l[2]) / 2.0};
}

} // namespace

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    const double d[3] = {direction.x, direction.y, direction.z};
    for (double c : d)
        if (!std::isfinite(c))
            return Color();
    if (d[0] == 0.0 && d[1] == 0.0 && d[2] == 0.0)
        return Color();

    thread_local Entry cache[1024] = {};
    std::uint64_t key[3];
    std::memcpy(key, d, sizeof key);
    const std::uint64_t h = (key[0] * 0x9E3779B97F4A7C15ull) ^ (key[1] * 0xC2B2AE3D27D4EB4Full) ^ (key[2] * 0x165667B19E3779F9ull);
    Entry& e = cache[(h >> 32) & 1023];
    if (!e.used || std::memcmp(e.key, key, sizeof key) != 0) {
        std::memcpy(e.key, key, sizeof key);
        e.hit = locate(d);
        e.used = true;
    }
    return readTexture(faceAddress(e.hit.face), e.hit.u, e.hit.v);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const double px = u * m_FaceWidth, py = v * m_FaceHeight;
    const int ix = (int)px, iy = (int)py;
    const double alpha = px - ix, beta = py - iy;
    const int x0 = std::min(std::max(ix, 0), m_FaceWidth - 1), x1 = std::min(std::max(ix + 1, 0), m_FaceWidth - 1);
    const int y0 = std::min(std::max(iy, 0), m_FaceHeight - 1), y1 = std::min(std::max(iy + 1, 0), m_FaceHeight - 1);
    const float* r0 = addr + 3 * y0 * m_FaceWidth;
    const float* r1 = addr + 3 * y1 * m_FaceWidth;
    Color out;
    double* o[3] = {&out.r, &out.g, &out.b};
    for (int k = 0; k < 3; ++k) {
        const double c0 = (1 - alpha) * r0[3 * x0 + k] + alpha * r0[3 * x1 + k];
        const double c1 = (1 - alpha) * r1[3 * x0 + k] + alpha * r1[3 * x1 + k];
        *o[k] = (1 - beta) * c0 + beta * c1;
    }
    return out;
}
