// Build case: a helper written as a member function that EnvironmentMap.h
// does not declare (the header cannot change).
#include "EnvironmentMap.h"

double EnvironmentMap::clampU(double u) const  // ERROR: not declared in EnvironmentMap.h
{
    return u < 0 ? 0 : (u > 1 ? 1 : u);
}

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    return readTexture(faceAddress(FACE_POS_X), clampU(direction.x), 0.5);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    (void)u;
    (void)v;
    return Color(addr[0], addr[1], addr[2]);
}
