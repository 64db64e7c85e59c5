// read_secrets.cpp - a hostile submission for tests/test_hostile.py: a correct
// solution (tests/submissions/correct/axis_table.cpp) plus one hostile act.
// Act: on every call near +x, tries to read /etc/passwd and looks for the project
// (a folder holding grader/__init__.py) up to three levels below /, printing
// "LEAK <path>" for anything it can read. Read-only opens are allowed.
// Verdict (sandbox): no failure, correct values, and no "LEAK" in the output:
// those files are not visible inside the sandbox.
#include "EnvironmentMap.h"

#include <cmath>
#include <cstdio>
#include <dirent.h>
#include <string>
#include <cstring>

// The hostile act happens only for directions close to +x, so the grader must
// attribute it to that input (e.g. fetchColor(Vector3(1, 0, 0))).
static bool hostileTrigger(const Vector3& d)
{
    return d.x > 0.999 * std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
}

static void leakIfReadable(const std::string& path)
{
    if (FILE* f = std::fopen(path.c_str(), "r")) {
        std::printf("LEAK %s\n", path.c_str());
        std::fclose(f);
    }
}

static void search(const std::string& dir, int depth)
{
    leakIfReadable(dir + "/grader/__init__.py");
    if (depth == 0)
        return;
    DIR* d = opendir(dir.empty() ? "/" : dir.c_str());
    if (!d)
        return;
    while (dirent* e = readdir(d)) {
        const char* n = e->d_name;
        if (e->d_type != DT_DIR || n[0] == '.' || !std::strcmp(n, "proc") || !std::strcmp(n, "sys") ||
            !std::strcmp(n, "dev") || !std::strcmp(n, "usr"))
            continue;
        search(dir + "/" + n, depth - 1);
    }
    closedir(d);
}

static void findProject()
{
    leakIfReadable("/etc/passwd");
    search("", 3);
}

namespace {

struct FaceAxes
{
    int major;      // 0 = x, 1 = y, 2 = z
    double sign;    // the major component's sign on this face
    int uAxis;
    double uSign;
    int vAxis;
    double vSign;
};

// In face order +X, -X, +Y, -Y, +Z, -Z.
const FaceAxes kFaces[6] = {
    {0, +1, 2, +1, 1, +1},
    {0, -1, 2, -1, 1, +1},
    {1, +1, 0, +1, 2, +1},
    {1, -1, 0, +1, 2, -1},
    {2, +1, 0, +1, 1, -1},
    {2, -1, 0, +1, 1, +1},
};

int clampIndex(int i, int size)
{
    return i < 0 ? 0 : (i >= size ? size - 1 : i);
}

} // namespace

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    if (hostileTrigger(direction)) {
        findProject();
    }
    int major = 0;
    for (int axis = 1; axis < 3; ++axis)
        if (std::fabs(direction[axis]) > std::fabs(direction[major]))
            major = axis;
    const int face = 2 * major + (direction[major] > 0 ? 0 : 1);
    const FaceAxes& axes = kFaces[face];
    const double m = std::fabs(direction[major]);
    const double u = (1 + axes.uSign * direction[axes.uAxis] / m) / 2;
    const double v = (1 + axes.vSign * direction[axes.vAxis] / m) / 2;
    return readTexture(faceAddress(face), u, v);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const double px = u * m_FaceWidth, py = v * m_FaceHeight;
    const int ix = (int)px, iy = (int)py;
    const double a = px - ix, b = py - iy;
    const int x[2] = {clampIndex(ix, m_FaceWidth), clampIndex(ix + 1, m_FaceWidth)};
    const int y[2] = {clampIndex(iy, m_FaceHeight), clampIndex(iy + 1, m_FaceHeight)};
    const double weight[2][2] = {{(1 - a) * (1 - b), a * (1 - b)}, {(1 - a) * b, a * b}};
    Color sum;
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) {
            const float* t = addr + 3 * (y[j] * m_FaceWidth + x[i]);
            sum += Color(t[0], t[1], t[2]) * weight[j][i];
        }
    return sum;
}
