// EXPECT: forbidden-object
// Attack: call something that is neither the standard library nor ours,
// hoping the link finds it somewhere (a grader-side helper, say).
#include "EnvironmentMap.h"

extern "C" double grader_expected_color(int channel);

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    (void)d;
    return Color(grader_expected_color(0), grader_expected_color(1), grader_expected_color(2));
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    (void)u;
    (void)v;
    return Color(addr[0], addr[1], addr[2]);
}
