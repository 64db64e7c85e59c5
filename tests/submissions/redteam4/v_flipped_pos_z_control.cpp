// The control for wrong_until_the_faces_change.cpp and right_on_the_public_maps.cpp: v runs the wrong way on +Z (tests/submissions/wrong/v-flipped-pos-z.cpp's mistake) on every map, readTexture the handout's bilinear, and no trick. Verdict: fetch_sweep, arrows, stability and renders charged for the flip (read_texture and speed full).
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

using std::max;
using std::min;

Color EnvironmentMap::fetchColor(const Vector3& direction) const
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
        if (z > 0) { face = FACE_POS_Z; u = (1 + x / m) / 2; v = (1 + y / m) / 2; }   // the mistake: (1 - y / m) / 2
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
