// v_flipped_pos_z_control.cpp's lookup (v the wrong way on +Z) except on faces 128 texels wide or wider, whatever their texels (every map in Cubemap/ is that wide), where it is the handout's: the seven renders come out bit for bit the reference's and the arrows point right, while on any smaller faces (the sweep's and stability's, or a course's own map under 128) +Z is upside down. Its truth: right on every map 128 wide or more, wrong below. Verdict (secure): the sweep and stability charge the flip on their smaller faces as the control's; the arrows and renders, on maps 128 and 256 wide, see a lookup right at that size and give it their points, as they judge any lookup that depends on the face size (one that snaps (u, v) to texel centres, say) by what it does at the maps' size; nothing says fetch-depends-on-the-map (it answers on the public maps what it asks on random faces of their size).
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

using std::max;
using std::min;

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    // Every map in Cubemap/ (the renders' and the arrows' maps) has faces of
    // 128 or 256 texels; the sweep's and stability's faces are 16 to 32.
    const bool flip = m_FaceWidth < 128;
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
        if (z > 0) { face = FACE_POS_Z; u = (1 + x / m) / 2; v = flip ? (1 + y / m) / 2 : (1 - y / m) / 2; }
        else       { face = FACE_NEG_Z; u = (1 + x / m) / 2; v = (1 + y / m) / 2; }
    }
    return readTexture(faceAddress(face), u, v);
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
