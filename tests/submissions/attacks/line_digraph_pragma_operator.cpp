// EXPECT: refused-source
// Attack: the same leak with the digraph %: for '#', the file named by a
// macro, and the warning through _Pragma built by token pasting.
#include "EnvironmentMap.h"

#define COURSE_FILE "/autograder/source/reference/src/lookup.c"
#define GLUE(a, b) a##b
#define SAY(x) GLUE(_Pra, gma)(#x)
%:line 40 COURSE_FILE
SAY(GCC warning "look")

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
