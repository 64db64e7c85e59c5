// EXPECT: refused-source
// Attack (issue 18): GCC quotes "line 19" of the file a #line names in its
// diagnostics, and a failed build's log goes to the student: the course
// secret out of the rubric.
#include "EnvironmentMap.h"

#line 19 "/autograder/source/grader/grading/rubric.toml"
#pragma GCC warning "look"
#line 3 "/autograder/source/reference/src/lookup.c"
#error "look"

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
