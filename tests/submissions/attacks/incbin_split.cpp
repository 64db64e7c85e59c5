// EXPECT: refused-source
// Attack: .incbin spelled across two string literals (no "incbin" in the
// text), to read a file into the program at assembly time.
#include "EnvironmentMap.h"

asm(".section .rodata\nstolen:\n\t.inc" "bin \"/etc/hostname\"\n\t.previous");

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
