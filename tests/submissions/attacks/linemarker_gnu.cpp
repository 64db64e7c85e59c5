// EXPECT: refused-source
// Attack: a GNU line marker (# 5 "file" 1 3) naming a system header, so a
// token scan that trusts markers would skip the asm that follows; and in
// PrairieLearn's layout it names the question's tests.
#include "EnvironmentMap.h"

# 5 "/usr/include/stdio.h" 1 3
asm(".pushsection .rodata; .inc" "bin \"/grade/tests/reference.so\"; .popsection");
# 20 "EnvironmentMap.cpp" 2

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
