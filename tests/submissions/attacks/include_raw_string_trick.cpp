// EXPECT: refused-include
// Attack: a digit separator then R"( so a naive lexer sees a raw string hiding the include.
#include "EnvironmentMap.h"
static const int big = 1'R"x(
#include "/etc/hostname"
)x";

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
