// EXPECT: refused-include
// Attack: read the grader's environment through /proc.
#include "EnvironmentMap.h"
#include </proc/self/environ>

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
