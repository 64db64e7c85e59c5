// EnvironmentMap.cpp - YOUR PART of the environment-mapping assignment.
//
// Write fetchColor and readTexture below. This file is your whole
// submission: the grader compiles it with its own copies of the other
// files, so keep your helper functions in this file too.
// Conventions (faces, (u, v) on each face, the buffer): README.md.
#include "EnvironmentMap.h"

#include <algorithm>

using std::max;
using std::min;

// The environment's colour in `direction` (not necessarily unit length).
Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    // TODO (handout, section 4 "About the program"; README.md, "Your task: fetchColor"):
    // pick the face that `direction` exits the cube through (the axis with
    // the largest absolute component), compute (u, v) on that face from the
    // table in README.md, and return readTexture(faceAddress(face), u, v).
    (void)direction; // delete this line once you use `direction`
    return Color(0.0, 0.0, 0.0);
}

// The colour of the face starting at `addr` at face parameters (u, v).
Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    // TODO (handout, section 4, equations (1)-(3); README.md, "Your task: readTexture"):
    // this returns the nearest texel, which shows blocks. Replace it with
    // bilinear interpolation of the 2x2 texels around (u*W, v*H), clamping
    // every texel coordinate to [0, W-1] and [0, H-1] as these lines do.
    const int x0 = max(0, min((int)(u * m_FaceWidth), m_FaceWidth-1));
    const int y0 = max(0, min((int)(v * m_FaceHeight), m_FaceHeight-1));
    const float* texel = addr + 3 * (y0 * m_FaceWidth + x0);
    return Color(texel[0], texel[1], texel[2]);
}
