// EXPECT: refused-source
// Attack (issue 18): the grader's own reference assembled into the program.
// The asm string is split (".inc" "bin": no "incbin" in the text) and a
// character constant '" makes a string regex disagree with GAS about where
// strings end, so .incbin reads /autograder/source/build/libenvmap.so into
// .rodata; a lookup could then call read_bilinear through its symbol table.
#include "EnvironmentMap.h"

asm(".pushsection .rodata\n\t.globl stolen_reference\nstolen_reference: .byte '\"; .inc" "bin \"/autograder/source/build/libenvmap.so\"\n\t.popsection");

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
