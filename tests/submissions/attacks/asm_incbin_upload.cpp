// EXPECT: refused-source
// Attack (issue 18): a binary blob uploaded beside the source
// (/autograder/submission/lookup.bin) assembled in with .incbin, spelled in
// raw strings and behind a macro so that no text holds the word.
#include "EnvironmentMap.h"

#define GLUE(a, b) a##b
#define ASM GLUE(__as, m__)
ASM(R"(.pushsection .rodata; .byte '"; .inc)" R"(bin "/autograder/submission/lookup.bin"; .popsection)");

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
