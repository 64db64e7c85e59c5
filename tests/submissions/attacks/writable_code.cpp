// EXPECT: refused-source
// Attack: make the ordinary .text section writable as well as executable
// (code that rewrites itself while it runs, e.g. after the checks looked).
#include "EnvironmentMap.h"

asm(".section .text.selfmod,\"awx\",@progbits\n\tnop\n\t.previous");

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
