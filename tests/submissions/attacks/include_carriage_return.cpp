// EXPECT: refused-include
// Attack: old Mac line ends: a lone carriage return ends a line for GCC, so the
// include after it is a directive (a checker splitting at \n sees none).
#include "EnvironmentMap.h"
int before_the_include;#include "/etc/hostname"int after_it;

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
