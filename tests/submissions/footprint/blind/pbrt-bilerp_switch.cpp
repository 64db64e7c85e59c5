// Written as pbrt-v4's Image::Bilerp reads a texture (graded blind, issue
// 29 item 6): pixel centres at half-integers, so x = u W - 0.5, then the
// four lattice points clamped (WrapMode::Clamp). Truth, from the code:
// half a texel off the handout's p = (uW, vH) on both axes, clamped edges.
#include "EnvironmentMap.h"

#include <algorithm>
#include <cmath>

Color EnvironmentMap::fetchColor(const Vector3& dir) const
{
    const double ax = std::abs(dir.x), ay = std::abs(dir.y), az = std::abs(dir.z);
    const int axis = (ax >= ay && ax >= az) ? 0 : (ay >= az ? 1 : 2);
    const double m = axis == 0 ? ax : axis == 1 ? ay : az;
    if (!(m > 0) || std::isinf(m) || std::isnan(dir.x + dir.y + dir.z))
        return Color(0, 0, 0);
    const double x = dir.x / m, y = dir.y / m, z = dir.z / m;
    int face;
    double u, v;
    switch (axis) {
    case 0:
        face = x > 0 ? FACE_POS_X : FACE_NEG_X;
        u = (1 + (x > 0 ? z : -z)) / 2;
        v = (1 + y) / 2;
        break;
    case 1:
        face = y > 0 ? FACE_POS_Y : FACE_NEG_Y;
        u = (1 + x) / 2;
        v = (1 + (y > 0 ? z : -z)) / 2;
        break;
    default:
        face = z > 0 ? FACE_POS_Z : FACE_NEG_Z;
        u = (1 + x) / 2;
        v = (1 + (z > 0 ? -y : y)) / 2;
        break;
    }
    return readTexture(faceAddress(face), u, v);
}

// readTexture:begin
namespace {
// WrapMode::Clamp: the coordinate held inside [0, n - 1].
int remapClamp(int c, int n) { return std::clamp(c, 0, n - 1); }
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    // Compute discrete pixel coordinates and offsets.
    const float x = float(u) * m_FaceWidth - 0.5f, y = float(v) * m_FaceHeight - 0.5f;
    const int xi = (int)std::floor(x), yi = (int)std::floor(y);
    const float dx = x - xi, dy = y - yi;
    // Load pixel channel values and return the bilinearly interpolated value.
    auto channel = [&](int px, int py, int c) {
        px = remapClamp(px, m_FaceWidth);
        py = remapClamp(py, m_FaceHeight);
        return addr[3 * (py * m_FaceWidth + px) + c];
    };
    float out[3];
    for (int c = 0; c < 3; ++c)
        out[c] = ((1 - dx) * (1 - dy) * channel(xi, yi, c) + dx * (1 - dy) * channel(xi + 1, yi, c) +
                  (1 - dx) * dy * channel(xi, yi + 1, c) + dx * dy * channel(xi + 1, yi + 1, c));
    return Color(out[0], out[1], out[2]);
}
// readTexture:end
