// Build case: includes a file by absolute path, which would print parts of
// a file on the grading machine in the compiler's messages; refused.
#include "EnvironmentMap.h"
#include "/etc/hostname"

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    (void)direction;
    return Color(0, 0, 0);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    (void)u;
    (void)v;
    return Color(addr[0], addr[1], addr[2]);
}
