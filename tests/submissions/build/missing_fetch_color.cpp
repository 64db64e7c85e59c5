// Build case: readTexture only; fetchColor is missing.
#include "EnvironmentMap.h"

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    (void)u;
    (void)v;
    return Color(addr[0], addr[1], addr[2]);
}
