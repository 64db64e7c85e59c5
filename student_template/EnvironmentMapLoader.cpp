// EnvironmentMapLoader.cpp - the provided parts of EnvironmentMap: reading a
// vertical-cross .hdr into faces. You do not need to change this file; the
// reading itself is the provided renderer's (renderer/src), so the grader
// and this program read maps the same way.
#include "EnvironmentMap.h"

#include "envmap.h"

bool EnvironmentMap::loadFromCrossHDR(const char* filename)
{
    em_cubemap cube = {};
    em_error error = {};
    if (em_cubemap_load_cross(filename, &cube, &error) != EM_OK) {
        m_LoadError = error.message;
        return false;
    }
    const std::size_t count = static_cast<std::size_t>(FACE_COUNT) * cube.face_width * cube.face_height * 3;
    m_OwnTexels.assign(cube.texels, cube.texels + count);
    m_FaceWidth = cube.face_width;
    m_FaceHeight = cube.face_height;
    em_cubemap_free(&cube);
    m_Texels = m_OwnTexels.data();
    m_LoadError.clear();
    return true;
}

void EnvironmentMap::attachFaces(const float* texels, int faceWidth, int faceHeight)
{
    m_OwnTexels.clear();
    m_OwnTexels.shrink_to_fit();
    m_FaceWidth = faceWidth;
    m_FaceHeight = faceHeight;
    m_Texels = texels;
}
