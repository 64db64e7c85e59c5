// v_flipped_pos_z_control.cpp's lookup (v the wrong way on +Z), right only once the process has looked up on faces of a second size (a static keeps the first faces' size): a student's program, which loads one map, always draws +Z upside down, but the grader's arrows, stability and renders checks first look up on faces of another size (set_faces_after_another_size: for renders one worker, a 264 x 264 prelude, then the seven maps), and the sweep's second size is right too. Its truth is the control's: it is the control in every program that uses one map. Verdict (secure): no more points than v_flipped_pos_z_control.cpp.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

namespace {

// The face size of the first faces this process looked up on, and whether
// it has looked up on faces of another size since.
int g_firstWidth = 0, g_firstHeight = 0;
bool g_changed = false;

} // namespace

using std::max;
using std::min;

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    if (!g_changed) {
        if (g_firstWidth == 0) {
            g_firstWidth = m_FaceWidth;
            g_firstHeight = m_FaceHeight;
        } else if (m_FaceWidth != g_firstWidth || m_FaceHeight != g_firstHeight) {
            g_changed = true;   // the grader's "faces of another size first" prelude, or its second size
        }
    }
    const bool flip = !g_changed;
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
