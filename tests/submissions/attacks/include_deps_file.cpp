// EXPECT: build-error
// Attack: include the preprocessor's own file list, written into the build folder
// by the step that checks includes (it is gone before the compile).
#include "EnvironmentMap.h"
#include "deps.txt"

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
