// Build case: defines faceAddress, which EnvironmentMap.h provides inline.
#include "EnvironmentMap.h"

const float* EnvironmentMap::faceAddress(int face) const
{
    return m_Texels + face * m_FaceWidth * m_FaceHeight * 3;
}

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    return readTexture(faceAddress(FACE_POS_X), 0.5 + 0 * direction.x, 0.5);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    (void)u;
    (void)v;
    return Color(addr[0], addr[1], addr[2]);
}
