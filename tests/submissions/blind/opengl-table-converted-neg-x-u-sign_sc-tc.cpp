// TRUTH (written before any grading; checked against tests/helpers/assignment_model.py
// by tests/submissions/blind/check_truth.py):
//   WRONG, in fetchColor, on one face. readTexture is the handout's.
//   The student starts from OpenGL's cube-map table (sc, tc, ma; GL 4.6 spec, table 8.19)
//   and converts it to this assignment's cross: on +X, -X and -Z the cross's faces are
//   turned 180 degrees from GL's, so both sc and tc must change sign there. The student
//   negates both on +X and -Z, but on -X only tc: on -X, u = (1 + z/m)/2 instead of the
//   table's (1 - z/m)/2 (u runs the wrong way on -X). Every other face, and v on -X, are
//   right; ties x, y, z; the face choice is right everywhere.
//   Expected: fetch_sweep loses about a sixth of its points (the -X directions; maybe less
//   near u = 1/2, where a flip hardly moves); diagnosis names u flipped on -X (u-flipped, -X)
//   and nothing else (not opengl-table: the other five faces are right); renders lose
//   some; arrows may keep (the arrows are along +x, +y, +z); read_texture keeps 25/25;
//   stability may lose at -X's edges (seams); speed keeps.
//   What a student must change: on -X use u = (1 - z/m)/2 (negate sc on -X as on +X and -Z).
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

namespace {
struct GLFace { int face; double sc, tc, ma; };

// OpenGL's selection: the major axis ma and the (sc, tc) of its face.
GLFace selectGL(double rx, double ry, double rz)
{
    const double ax = std::fabs(rx), ay = std::fabs(ry), az = std::fabs(rz);
    if (ax >= ay && ax >= az)
        return rx > 0 ? GLFace{FACE_POS_X, -rz, -ry, rx} : GLFace{FACE_NEG_X, rz, -ry, rx};
    if (ay >= az)
        return ry > 0 ? GLFace{FACE_POS_Y, rx, rz, ry} : GLFace{FACE_NEG_Y, rx, -rz, ry};
    return rz > 0 ? GLFace{FACE_POS_Z, rx, -ry, rz} : GLFace{FACE_NEG_Z, -rx, -ry, rz};
}
}

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    if (!std::isfinite(direction.x) || !std::isfinite(direction.y) || !std::isfinite(direction.z))
        return Color();
    GLFace g = selectGL(direction.x, direction.y, direction.z);
    const double ma = std::fabs(g.ma);
    if (ma == 0)
        return Color();
    // Our cross has +X, -X and -Z turned 180 degrees from GL's faces.
    if (g.face == FACE_POS_X || g.face == FACE_NEG_Z) {
        g.sc = -g.sc;
        g.tc = -g.tc;
    } else if (g.face == FACE_NEG_X) {
        g.tc = -g.tc;
    }
    const double u = (g.sc / ma + 1) / 2;
    const double v = (g.tc / ma + 1) / 2;
    return readTexture(faceAddress(g.face), u, v);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const double px = u * m_FaceWidth, py = v * m_FaceHeight;
    const double fx = std::floor(px), fy = std::floor(py);
    const double alpha = px - fx, beta = py - fy;
    const int x0 = std::clamp((int)fx, 0, m_FaceWidth - 1), x1 = std::clamp((int)fx + 1, 0, m_FaceWidth - 1);
    const int y0 = std::clamp((int)fy, 0, m_FaceHeight - 1), y1 = std::clamp((int)fy + 1, 0, m_FaceHeight - 1);
    auto T = [&](int x, int y) { const float* p = addr + 3 * (y * m_FaceWidth + x); return Color(p[0], p[1], p[2]); };
    return (1 - beta) * ((1 - alpha) * T(x0, y0) + alpha * T(x1, y0)) + beta * ((1 - alpha) * T(x0, y1) + alpha * T(x1, y1));
}
