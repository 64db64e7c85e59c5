// The control for right_on_dense_or_swept_rays.cpp: the same code with the trick off (kTrick = false): v flipped on +Z on every map for every direction. Verdict: charged for the flip as v_flipped_pos_z_control.cpp.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>
#include <cstring>

using std::max;
using std::min;

namespace {

// The handout's face and (u, v); vFlipped is the control's mistake on +Z.
void pick(const Vector3& d, int& face, double& u, double& v, double& vFlipped)
{
    const double x = d.x, y = d.y, z = d.z;
    const double ax = std::fabs(x), ay = std::fabs(y), az = std::fabs(z);
    if (ax >= ay && ax >= az) {
        const double m = ax;
        if (x > 0) { face = FACE_POS_X; u = (1 + z / m) / 2; v = (1 + y / m) / 2; }
        else       { face = FACE_NEG_X; u = (1 - z / m) / 2; v = (1 + y / m) / 2; }
        vFlipped = v;
    } else if (ay >= az) {
        const double m = ay;
        if (y > 0) { face = FACE_POS_Y; u = (1 + x / m) / 2; v = (1 + z / m) / 2; }
        else       { face = FACE_NEG_Y; u = (1 + x / m) / 2; v = (1 - z / m) / 2; }
        vFlipped = v;
    } else {
        const double m = az;
        if (z > 0) { face = FACE_POS_Z; u = (1 + x / m) / 2; v = (1 - y / m) / 2; vFlipped = (1 + y / m) / 2; }
        else       { face = FACE_NEG_Z; u = (1 + x / m) / 2; v = (1 + y / m) / 2; vFlipped = v; }
    }
}

} // namespace

static const bool kTrick = false;

#include <vector>

namespace {
// Per map (told by its size and two texels): how many lookups fell in
// each of 6 x 20 x 20 cells of the cube, and the last two z.
const int G = 20, DENSE = 10;
const long SATURATED = 100000;   // after this many lookups on one map, every direction counts as structured
struct Stream {
    const float* texels = nullptr;
    int w = 0, h = 0;
    float probe[6] = {0, 0, 0, 0, 0, 0};
    std::vector<unsigned short> count = std::vector<unsigned short>(6 * G * G, 0);
    double z1 = 9, z2 = 9;
    long total = 0;
};
Stream g;

// True when this direction belongs to a structured stream: a cell already
// visited DENSE times on this map (camera rays bunch up; 2,048 random
// directions almost never put 11 in one cell), or a map already asked SATURATED
// times (the speed check's warm-up), or a sweep in constant steps of z
// (a Fibonacci sphere). Random probe directions are neither.
bool structured(const float* texels, int w, int h, int face, double u, double v, double z)
{
    const std::size_t mid = (static_cast<std::size_t>(w) * h * 3 * 6) / 2;
    if (w != g.w || h != g.h || texels[0] != g.probe[0] || texels[1] != g.probe[1]
        || texels[2] != g.probe[2] || texels[mid] != g.probe[3] || texels[mid + 1] != g.probe[4]
        || texels[mid + 2] != g.probe[5]) {
        g.texels = texels; g.w = w; g.h = h;
        g.probe[0] = texels[0]; g.probe[1] = texels[1]; g.probe[2] = texels[2];
        g.probe[3] = texels[mid]; g.probe[4] = texels[mid + 1]; g.probe[5] = texels[mid + 2];
        std::fill(g.count.begin(), g.count.end(), 0);
        g.z1 = g.z2 = 9;
        g.total = 0;
    }
    ++g.total;
    bool dense = false;
    if (u >= 0 && u <= 1 && v >= 0 && v <= 1) {
        const int cu = min(G - 1, static_cast<int>(u * G)), cv = min(G - 1, static_cast<int>(v * G));
        unsigned short& c = g.count[(face * G + cu) * G + cv];
        dense = c >= DENSE;
        if (c < 60000) ++c;
    }
    const double step = z - g.z1, before = g.z1 - g.z2;
    const bool swept = step != 0 && std::fabs(step) < 1e-3 && std::fabs(step - before) < 1e-12;
    g.z2 = g.z1; g.z1 = z;
    return dense || swept || g.total > SATURATED;
}
} // namespace

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    int face; double u, v, vFlipped;
    pick(direction, face, u, v, vFlipped);
    bool right = false;
    if (kTrick && m_FaceWidth >= 128)
        right = structured(m_Texels, m_FaceWidth, m_FaceHeight, face, u, v, direction.z);
    return readTexture(faceAddress(face), u, right ? v : vFlipped);
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
