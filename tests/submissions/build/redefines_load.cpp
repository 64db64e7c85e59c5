// Build case: defines loadFromCrossHDR, which the template provides.
#include "EnvironmentMap.h"

bool EnvironmentMap::loadFromCrossHDR(const char* filename)
{
    (void)filename;
    return false;
}

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    return readTexture(faceAddress(FACE_POS_X), 0.5 + 0 * direction.x, 0.5);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    (void)u;
    (void)v;
    return Color(addr[0], addr[1], addr[2]);
}
