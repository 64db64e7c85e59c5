// EXPECT: refused-include
// Attack: include a file of the build folder that is not an API header.
#include "EnvironmentMap.h"
#include "allowed-symbols.txt"

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
