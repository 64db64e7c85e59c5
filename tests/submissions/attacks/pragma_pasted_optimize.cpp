// EXPECT: refused-source
// Attack: a pragma the text cannot see (_Pragma built by token pasting),
// here one that changes how the grader's flags compile the file.
#include "EnvironmentMap.h"

#define GLUE(a, b) a##b
#define SAY(x) GLUE(_Pra, gma)(#x)
SAY(GCC optimize("no-inline"))

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
