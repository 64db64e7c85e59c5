// The control for right_on_the_public_texels.cpp: the same code with the trick off (kTrick = false): it reads the first texel of face 0 but v is flipped on +Z on every map. Verdict: charged for the flip in fetch_sweep, arrows, stability and renders, as v_flipped_pos_z_control.cpp.
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

namespace {
// The first texel of face 0 of each map in Cubemap/ (grid_room_cross, interior_cross, sky_cross, test_environment_map).
const float kPublic[4][3] = {{0.1494140625f, 0.1494140625f, 0.1494140625f}, {0.45703125f, 0.279296875f, 0.140625f},
                              {1.765625f, 1.828125f, 2.015625f}, {0.3984375f, 0.3984375f, 0.3984375f}};
} // namespace

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    int face; double u, v, vFlipped;
    pick(direction, face, u, v, vFlipped);
    const float* first = faceAddress(0);
    bool publicMap = false;
    for (const auto& t : kPublic)
        publicMap = publicMap || (first[0] == t[0] && first[1] == t[1] && first[2] == t[2]);
    return readTexture(faceAddress(face), u, kTrick && publicMap ? v : vFlipped);
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
