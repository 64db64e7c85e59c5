// Written as a software renderer's texture unit samples with REPEAT on both
// axes (graded blind, issue 29 item 6): texel centres at half-integers,
// coordinates wrapped with a positive modulo before and after the step.
// Truth, from the code: half a texel off on both axes, and the edges wrap
// (the left column blends with the right one, the bottom row with the top).
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

namespace {
// One row per face: the major axis and its sign, then u and v as
// (1 + sign * component / m) / 2 (README.md's table).
struct FaceRow { int face, axis; double sign; int uAxis; double uSign; int vAxis; double vSign; };
const FaceRow kFaces[6] = {
    {FACE_POS_X, 0, +1, 2, +1, 1, +1},
    {FACE_NEG_X, 0, -1, 2, -1, 1, +1},
    {FACE_POS_Y, 1, +1, 0, +1, 2, +1},
    {FACE_NEG_Y, 1, -1, 0, +1, 2, -1},
    {FACE_POS_Z, 2, +1, 0, +1, 1, -1},
    {FACE_NEG_Z, 2, -1, 0, +1, 1, +1},
};
}

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    const double c[3] = {direction.x, direction.y, direction.z};
    int major = 0;
    for (int a = 1; a < 3; ++a)
        if (std::fabs(c[a]) > std::fabs(c[major]))
            major = a;
    const double m = std::fabs(c[major]);
    if (!(m > 0) || !std::isfinite(m) || std::isnan(c[0] + c[1] + c[2]))
        return Color();
    const FaceRow& f = kFaces[2 * major + (c[major] < 0 ? 1 : 0)];
    const double u = 0.5 * (1 + f.uSign * c[f.uAxis] / m);
    const double v = 0.5 * (1 + f.vSign * c[f.vAxis] / m);
    return readTexture(faceAddress(f.face), u, v);
}

// readTexture:begin
namespace {
struct Sampler {
    const float* texels;
    int width, height;
    static int wrap(int i, int n) { int r = i % n; return r < 0 ? r + n : r; }
    void fetch(int x, int y, float w, float* acc) const {
        const float* t = texels + 3 * (wrap(y, height) * width + wrap(x, width));
        for (int c = 0; c < 3; ++c) acc[c] += w * t[c];
    }
    Color sample(double s, double t) const {
        const double x = s * width - 0.5, y = t * height - 0.5;
        const int x0 = (int)std::floor(x), y0 = (int)std::floor(y);
        const float fx = (float)(x - x0), fy = (float)(y - y0);
        float acc[3] = {0, 0, 0};
        fetch(x0, y0, (1 - fx) * (1 - fy), acc);
        fetch(x0 + 1, y0, fx * (1 - fy), acc);
        fetch(x0, y0 + 1, (1 - fx) * fy, acc);
        fetch(x0 + 1, y0 + 1, fx * fy, acc);
        return Color(acc[0], acc[1], acc[2]);
    }
};
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    return Sampler{addr, m_FaceWidth, m_FaceHeight}.sample(u, v);
}
// readTexture:end
