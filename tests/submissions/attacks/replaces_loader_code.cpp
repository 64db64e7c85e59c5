// EXPECT: forbidden-object
// Attack: define a function of the reference code the loader is linked
// with (em_fail), silently replacing it inside the grader's loader, e.g.
// to learn when the grader loads a map.
#include "EnvironmentMap.h"

#include <cstdarg>

extern "C" int em_fail(void* err, int code, const char* name, const char* fmt, ...)
{
    (void)err;
    (void)name;
    (void)fmt;
    return code;
}

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
