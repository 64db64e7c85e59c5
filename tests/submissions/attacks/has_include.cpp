// EXPECT: refused-include
// Attack: probe for files on the grading machine.
#include "EnvironmentMap.h"
#if __has_include("/work/main/fixtures/manifest.json")
#define ON_GRADER 1
#endif

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
