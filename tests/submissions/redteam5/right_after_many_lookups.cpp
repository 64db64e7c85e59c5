// v_flipped_pos_z_control.cpp's lookup except on faces 128 wide or more after 4,096 lookups on the same map (told by its buffer, width and first texel): the map probe asks 2,048 directions per map and sees +Z flipped there as on the 32x32 faces (no difference), while each render asks ~125,000 and gets the handout's lookup for all but its first 4,096 rays (the arrows' first 4,096 directions, the caps and the Fibonacci sphere's top around +z, stay flipped). Its truth is the control's. Verdict (secure): no more points than right_after_many_lookups_control.cpp.
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

static const bool kTrick = true;

namespace {
// Lookups made on the current map (told by its buffer, size and first texel).
const float* g_texels = nullptr;
int g_w = 0;
float g_first = -1;
long g_lookups = 0;
const long AFTER = 4096;    // the map probe asks 2,048 directions per map; a render asks ~125,000
}

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    if (m_Texels != g_texels || m_FaceWidth != g_w || m_Texels[0] != g_first) {
        g_texels = m_Texels; g_w = m_FaceWidth; g_first = m_Texels[0]; g_lookups = 0;
    }
    ++g_lookups;
    int face; double u, v, vFlipped;
    pick(direction, face, u, v, vFlipped);
    const bool right = kTrick && m_FaceWidth >= 128 && g_lookups > AFTER;
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
