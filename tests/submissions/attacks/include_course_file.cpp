// EXPECT: refused-include
// Attack: the course's rubric included by its path, to read the secret in
// the compiler's error messages.
#include "EnvironmentMap.h"
#include "/autograder/source/grader/grading/rubric.toml"

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
