// EXPECT: refused-source
// Attack: data in a section no C++ compiler makes (here one the dynamic
// loader reads), to steer the linker or the loader.
#include "EnvironmentMap.h"

__attribute__((section(".preinit_hack"), used)) static const char note[] = "hello";

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    (void)d;
    return Color(0, 0, 0);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    (void)u;
    (void)v;
    return Color(addr[0], addr[1], addr[2]);
}
