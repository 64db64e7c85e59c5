// EXPECT: refused-source
// Attack: LTO bytes placed with a section attribute instead of asm.
#include "EnvironmentMap.h"

__attribute__((section(".gnu.lto_.opts"), used)) static const char opts[] = "'-fno-openmp'";

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
