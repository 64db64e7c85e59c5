// Build case: includes a header of the original 2014 code that the
// template does not have.
#include "EnvironmentMap.h"
#include "hdr.h"  // ERROR: no such header in the template

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
