// EXPECT: refused-source
// Attack: flood the report through the refusal message: hundreds of
// undefined symbols with very long names, one with a newline in it.
#include "EnvironmentMap.h"

#define REF(n) asm(".reloc ., R_X86_64_NONE, \"" #n "_aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa\"");
#define REF10(n) REF(n##0) REF(n##1) REF(n##2) REF(n##3) REF(n##4) REF(n##5) REF(n##6) REF(n##7) REF(n##8) REF(n##9)
REF10(s1) REF10(s2) REF10(s3) REF10(s4) REF10(s5) REF10(s6) REF10(s7) REF10(s8) REF10(s9)
asm(".reloc ., R_X86_64_NONE, \"line\\nbreak\"");

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
