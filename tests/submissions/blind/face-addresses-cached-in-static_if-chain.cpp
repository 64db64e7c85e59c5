// TRUTH (written before any grading; checked against tests/helpers/assignment_model.py
// by tests/submissions/blind/check_truth.py):
//   WRONG, in fetchColor, only once the map's faces change in a process. readTexture is
//   the handout's. The face choice and (u, v) are right (if-chain, ties x, y, z).
//   The mistake (an engine habit: "look the faces up once"): fetchColor keeps the six face
//   addresses in a function-local static array filled at its FIRST call
//   (faceAddress(0..5) of the map it was first called on). While that map keeps its
//   buffer, every answer is right. After attachFaces/loadFromCrossHDR puts the faces in
//   another buffer (another map, a reload, another face size), fetchColor still passes the
//   OLD buffer's face addresses: it reads stale (or freed) memory, with the new W and H.
//   Expected: whatever the grader runs after the first buffer in the same process is
//   wrong: at least the fetch_sweep set "24 x 16 faces after 32 x 32" (the address passed
//   is not a face start of the current map), so fetch_sweep loses points; other checks
//   lose points or crash if they reuse the process with a new buffer, keep them if they
//   start a fresh process. read_texture keeps 25/25. Expected id: the address is not a
//   face start / state kept between calls (address-not-face-start or kept-between-calls),
//   no u/v/face mistake.
//   What a student must change: call faceAddress(face) on every call; keep nothing about
//   the map in statics.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    static const float* faces[6] = {faceAddress(0), faceAddress(1), faceAddress(2),
                                    faceAddress(3), faceAddress(4), faceAddress(5)};
    double x = direction.x, y = direction.y, z = direction.z;
    double ax = std::fabs(x), ay = std::fabs(y), az = std::fabs(z);
    if (!(std::isfinite(ax) && std::isfinite(ay) && std::isfinite(az)))
        return Color();
    if (ax >= ay && ax >= az) {
        if (ax == 0)
            return Color();
        if (x > 0)
            return readTexture(faces[FACE_POS_X], (1 + z / ax) / 2, (1 + y / ax) / 2);
        else
            return readTexture(faces[FACE_NEG_X], (1 - z / ax) / 2, (1 + y / ax) / 2);
    } else if (ay >= az) {
        if (y > 0)
            return readTexture(faces[FACE_POS_Y], (1 + x / ay) / 2, (1 + z / ay) / 2);
        else
            return readTexture(faces[FACE_NEG_Y], (1 + x / ay) / 2, (1 - z / ay) / 2);
    } else {
        if (z > 0)
            return readTexture(faces[FACE_POS_Z], (1 + x / az) / 2, (1 - y / az) / 2);
        else
            return readTexture(faces[FACE_NEG_Z], (1 + x / az) / 2, (1 + y / az) / 2);
    }
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const double px = u * m_FaceWidth, py = v * m_FaceHeight;
    const int x0 = std::min(std::max((int)px, 0), m_FaceWidth - 1);
    const int y0 = std::min(std::max((int)py, 0), m_FaceHeight - 1);
    const int x1 = std::min(x0 + 1, m_FaceWidth - 1);
    const int y1 = std::min(y0 + 1, m_FaceHeight - 1);
    const double alpha = px - (int)px, beta = py - (int)py;
    const float* row0 = addr + 3 * y0 * m_FaceWidth;
    const float* row1 = addr + 3 * y1 * m_FaceWidth;
    auto at = [](const float* row, int x) { return Color(row[3 * x], row[3 * x + 1], row[3 * x + 2]); };
    const Color c0 = at(row0, x0) * (1 - alpha) + at(row0, x1) * alpha;
    const Color c1 = at(row1, x0) * (1 - alpha) + at(row1, x1) * alpha;
    return c0 * (1 - beta) + c1 * beta;
}
