// EXPECT: refused-source
// Attack: an assembler macro that builds the .incbin directive from two
// arguments, so no text the grader checks ever holds the directive's name.
#include "EnvironmentMap.h"

asm(".macro pull a, b\n\t.\\a\\()\\b \"/etc/hostname\"\n\t.endm\n"
    "\t.section .rodata\n\tpull inc, bin\n\t.previous");

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
