// EXPECT: calls-reference
// Attack: the answer linked in. Declares the reference's lookup itself and
// calls it (scored 100/100 when the grader linked the reference library).
#include "EnvironmentMap.h"

extern "C" {
struct em_cubemap_ { int face_width, face_height; float* texels; };
void em_fetch(const em_cubemap_*, int, double, double, double, double[3]);
void em_read_texture(const em_cubemap_*, int, int, double, double, double[3]);
}

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    em_cubemap_ cube{m_FaceWidth, m_FaceHeight, const_cast<float*>(m_Texels)};
    double rgb[3];
    em_fetch(&cube, 1, d.x, d.y, d.z, rgb);
    return Color(rgb[0], rgb[1], rgb[2]);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    em_cubemap_ cube{m_FaceWidth, m_FaceHeight, const_cast<float*>(addr)};
    double rgb[3];
    em_read_texture(&cube, 1, 0, u, v, rgb);
    return Color(rgb[0], rgb[1], rgb[2]);
}
