// v_flipped_pos_z_control.cpp's lookup except that, on +Z, it first asks readTexture at the handout's (u, v) and keeps that answer when the faces are 128 wide or more and the answer is not one of the grader's four recording tags (fetch_record.TAGS, copied here); otherwise it asks again at the flipped v and returns that. Recorded (tags come back) it makes the same two calls and returns the flipped one on every face size, so the map probe sees no difference; unrecorded on the public maps (arrows, renders) it returns the handout's colour. Its truth is the control's. Verdict (secure): no more points than knows_the_tags_control.cpp.
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
// The grader's recording answers (grader/checks/instruments/fetch_record.py TAGS).
const double kTags[4][3] = {{0.359375, 0.6171875, 0.2265625}, {0.7265625, 0.1953125, 0.5390625},
                            {0.4453125, 0.8203125, 0.6640625}, {0.2890625, 0.4140625, 0.9296875}};
bool isTag(const Color& c)
{
    for (const auto& t : kTags)
        if (c.r == t[0] && c.g == t[1] && c.b == t[2])
            return true;
    return false;
}
} // namespace

// On +Z: ask the handout's (u, v) first; keep that answer only when it is a
// real colour (not a grader tag) on faces 128 wide or more, else ask the
// flipped v and return that. Recorded, the calls are the same on every face size.
Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    int face; double u, v, vFlipped;
    pick(direction, face, u, v, vFlipped);
    const float* addr = faceAddress(face);
    if (face != FACE_POS_Z)
        return readTexture(addr, u, v);
    const Color first = readTexture(addr, u, v);
    if (kTrick && m_FaceWidth >= 128 && !isTag(first))
        return first;
    return readTexture(addr, u, vFlipped);
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
