// Build case: extra global symbols (a class, functions, variables, even a
// main) are fine; the build succeeds. It also has one -Wall warning.
#include "EnvironmentMap.h"

#include <cstdio>
#include <map>
#include <string>

int g_calls = 0;
std::map<std::string, int> g_statistics;

class Helper
{
public:
    double twice(double x) const { return 2 * x; }
};

double square(double x)
{
    return x * x;
}

int main()
{
    std::printf("a stray main left in by a student\n");
    return 0;
}

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    int unused = 0;  // WARNING: unused variable
    ++g_calls;
    return readTexture(faceAddress(FACE_POS_X), Helper().twice(0.25) + 0 * square(direction.x), 0.5);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    (void)u;
    (void)v;
    return Color(addr[0], addr[1], addr[2]);
}
