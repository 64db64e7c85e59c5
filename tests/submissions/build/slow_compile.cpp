// Build case: compiling this takes minutes (a compile-time loop of about
// 10^10 steps); the build's time limit must stop it.
#include "EnvironmentMap.h"

constexpr long busy()
{
    long sum = 0;
    for (long i = 0; i < 200000; ++i)
        for (long j = 0; j < 200000; ++j)
            sum += i ^ j;
    return sum;
}

static_assert(busy() != 0, "computed at compile time");

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
