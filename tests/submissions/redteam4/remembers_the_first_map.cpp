// correct_control.cpp's lookup behind a cache of answers keyed by the direction alone: right on the first map a process looks a direction up on, and, once the map changes, a direction asked again gets the old map's colour. Recorded checks re-record remembered answers in a fresh worker (instruments.fetch_record.record); the renders now share one worker, and four of them trace the same scene (envmap_test.cfg's camera paths) on grid_room, interior, sky and the test map in turn, so from the second of those on its answers are the first map's. Its truth: right in a program that loads one map, wrong once it loads another: the renders after the first on the same scene should be charged (renders below correct_control.cpp's), and nothing else. Verdict (secure): renders below full, the other checks as correct_control.cpp's.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

namespace {

// A direct-mapped cache of answers, keyed by the direction's bits alone (not
// by the map): a student's speed-up that is right in a program that loads
// one map, and answers a second map's lookups with the first map's colours.
struct Slot
{
    double key[3];
    Color colour;
    bool used;
};

constexpr std::size_t SLOTS = std::size_t(1) << 18;
std::vector<Slot> g_cache(SLOTS);

std::size_t slotOf(const double key[3])
{
    std::uint64_t h = 1469598103934665603ull;
    for (int i = 0; i < 3; ++i) {
        std::uint64_t bits;
        std::memcpy(&bits, &key[i], sizeof bits);
        h = (h ^ bits) * 1099511628211ull;
        h ^= h >> 29;
    }
    return static_cast<std::size_t>(h & (SLOTS - 1));
}

} // namespace

static Color lookUp(const EnvironmentMap& map, const Vector3& direction);

using std::max;
using std::min;

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    const double key[3] = {direction.x, direction.y, direction.z};
    Slot& slot = g_cache[slotOf(key)];
    if (slot.used && std::memcmp(slot.key, key, sizeof key) == 0)
        return slot.colour;
    const Color c = lookUp(*this, direction);
    std::memcpy(slot.key, key, sizeof key);
    slot.colour = c;
    slot.used = true;
    return c;
}

static Color lookUp(const EnvironmentMap& map, const Vector3& direction)
{
    const double x = direction.x, y = direction.y, z = direction.z;
    const double ax = std::fabs(x), ay = std::fabs(y), az = std::fabs(z);
    int face;
    double u, v;
    if (ax >= ay && ax >= az) {
        const double m = ax;
        if (x > 0) { face = FACE_POS_X; u = (1 + z / m) / 2; v = (1 + y / m) / 2; }
        else       { face = FACE_NEG_X; u = (1 - z / m) / 2; v = (1 + y / m) / 2; }
    } else if (ay >= az) {
        const double m = ay;
        if (y > 0) { face = FACE_POS_Y; u = (1 + x / m) / 2; v = (1 + z / m) / 2; }
        else       { face = FACE_NEG_Y; u = (1 + x / m) / 2; v = (1 - z / m) / 2; }
    } else {
        const double m = az;
        if (z > 0) { face = FACE_POS_Z; u = (1 + x / m) / 2; v = (1 - y / m) / 2; }
        else       { face = FACE_NEG_Z; u = (1 + x / m) / 2; v = (1 + y / m) / 2; }
    }
    return map.readTexture(map.faceAddress(face), u, v);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const double px = u * m_FaceWidth, py = v * m_FaceHeight;
    const int xf = (int)std::floor(px), yf = (int)std::floor(py);
    const double alpha = px - xf, beta = py - yf;
    const int x0 = max(0, min(xf, m_FaceWidth - 1)), x1 = max(0, min(xf + 1, m_FaceWidth - 1));
    const int y0 = max(0, min(yf, m_FaceHeight - 1)), y1 = max(0, min(yf + 1, m_FaceHeight - 1));
    const float* c00 = addr + 3 * (y0 * m_FaceWidth + x0);
    const float* c10 = addr + 3 * (y0 * m_FaceWidth + x1);
    const float* c01 = addr + 3 * (y1 * m_FaceWidth + x0);
    const float* c11 = addr + 3 * (y1 * m_FaceWidth + x1);
    double c[3];
    for (int i = 0; i < 3; ++i) {
        const double c0 = (1 - alpha) * c00[i] + alpha * c10[i];
        const double c1 = (1 - alpha) * c01[i] + alpha * c11[i];
        c[i] = (1 - beta) * c0 + beta * c1;
    }
    return Color(c[0], c[1], c[2]);
}
