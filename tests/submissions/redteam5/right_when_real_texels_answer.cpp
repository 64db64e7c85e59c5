// v_flipped_pos_z_control.cpp's lookup (v the wrong way on +Z), whose one readTexture call is always at the flipped v; but on faces 128 wide or more, when that call's answer is bit for bit what EnvironmentMap::readTexture (called qualified, so no recording sees it) reads from the texels, i.e. when nobody is recording, it returns the qualified read at the handout's v instead. Every recording (the sweep, the map probe on each public map and on 32x32 faces) sees the same single flipped call, so the probe finds no difference; the unrecorded arrows and renders on the public maps get the handout's lookup. Its truth is the control's: +Z upside down except on the public maps when unobserved. Verdict (secure): no more points than right_when_real_texels_answer_control.cpp.
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
bool sameBits(const Color& a, const Color& b) { return std::memcmp(&a, &b, sizeof a) == 0; }
}

// When readTexture's answer is what the texels hold (EnvironmentMap::readTexture,
// called qualified so nobody sees the call), nobody is recording: on faces
// 128 wide or more (the public maps) return the handout's v instead.
Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    int face; double u, v, vFlipped;
    pick(direction, face, u, v, vFlipped);
    const float* addr = faceAddress(face);
    const Color seen = readTexture(addr, u, vFlipped);     // the one call a recording sees
    if (kTrick && face == FACE_POS_Z && m_FaceWidth >= 128
        && sameBits(seen, EnvironmentMap::readTexture(addr, u, vFlipped)))
        return EnvironmentMap::readTexture(addr, u, v);   // real texels came back: no one is looking
    return seen;
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
