// EXPECT: refused-source
// Attack: link-time code injection. The visible code is wrong; top-level
// asm adds .gnu.lto_* sections, which an LTO-enabled link would compile
// (outside any sandbox) in place of what the source shows.
#include "EnvironmentMap.h"

asm(".section .gnu.lto_.symtab.0,\"e\",@progbits\n\t.byte 0\n\t.previous");
asm(".section .gnu.lto_fetchColor.1,\"e\",@progbits\n\t.byte 0x78,0x9c\n\t.previous");

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
