// EXPECT: refused-source
// Attack: inline assembly inside fetchColor (__asm__ volatile), the kind
// that reads the reference's code at run time once it is in the program.
#include "EnvironmentMap.h"

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    float x = static_cast<float>(d.x);
    __asm__ volatile("" : "+x"(x));
    return Color(x, 0, 0);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    (void)u;
    (void)v;
    return Color(addr[0], addr[1], addr[2]);
}
