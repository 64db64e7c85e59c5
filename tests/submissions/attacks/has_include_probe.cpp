// EXPECT: build-error
// Attack: __has_include built by token pasting (the text check cannot see
// it) probes whether a course file exists; the answer comes back in the
// build log. The confined compiler must see no course file: NOTFOUND.
#include "EnvironmentMap.h"

#define GLUE(a, b) a##b
#define PROBE GLUE(__has_, include)
#if PROBE("/autograder/source/build/libenvmap.so")
#error "FOUND the course file"
#else
#error "NOTFOUND"
#endif

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
