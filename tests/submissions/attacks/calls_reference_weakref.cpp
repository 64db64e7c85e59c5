// EXPECT: refused-source
// Attack: reach the reference through an assembler alias, so that the
// source never names em_fetch as a function.
#include "EnvironmentMap.h"

asm(".weakref lookup_alias, em_fetch_batch");
extern "C" void lookup_alias(const void*, int, const double*, unsigned long, double*, int*);

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    struct { int w, h; const float* t; } cube{m_FaceWidth, m_FaceHeight, m_Texels};
    double dir[3] = {d.x, d.y, d.z}, rgb[3];
    lookup_alias(&cube, 1, dir, 1, rgb, nullptr);
    return Color(rgb[0], rgb[1], rgb[2]);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    (void)u;
    (void)v;
    return Color(addr[0], addr[1], addr[2]);
}
