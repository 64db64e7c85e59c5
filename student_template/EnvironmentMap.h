// EnvironmentMap.h - a cube-map environment: six square faces read from a
// vertical-cross .hdr file.
//
// Provided with the template: DO NOT EDIT. You write fetchColor and
// readTexture in EnvironmentMap.cpp; the grader compiles that one file with
// its own copy of this header.
//
// Conventions (README.md, "Conventions"):
//   - faces are numbered 0..5 in the order +X, -X, +Y, -Y, +Z, -Z
//     (FACE_POS_X .. FACE_NEG_Z below);
//   - the texels are one float RGB buffer m_FaceWidth wide and
//     6 * m_FaceHeight tall: face k starts at k * m_FaceWidth * m_FaceHeight * 3
//     floats (faceAddress(k)); inside a face, texel (x, y) is at
//     addr[3 * (y * m_FaceWidth + x)], x = 0 the left column (u = 0) and
//     y = 0 the bottom row (v = 0).
#ifndef ENVIRONMENT_MAP_H
#define ENVIRONMENT_MAP_H

#include <cstddef>
#include <string>
#include <vector>

#include "Color.h"
#include "Vector3.h"

// Cube faces, in buffer order.
enum CubeFace
{
    FACE_POS_X = 0,
    FACE_NEG_X = 1,
    FACE_POS_Y = 2,
    FACE_NEG_Y = 3,
    FACE_POS_Z = 4,
    FACE_NEG_Z = 5,
    FACE_COUNT = 6
};

class EnvironmentMap
{
public:
    EnvironmentMap() = default;
    // Not copyable: m_Texels may point into this object's own storage.
    EnvironmentMap(const EnvironmentMap&) = delete;
    EnvironmentMap& operator=(const EnvironmentMap&) = delete;

    // Provided (EnvironmentMapLoader.cpp): read a Radiance .hdr vertical
    // cross and cut it into the six faces. false on failure; loadError()
    // says why.
    bool loadFromCrossHDR(const char* filename);
    const std::string& loadError() const { return m_LoadError; }

    // Provided (EnvironmentMapLoader.cpp): use six faces of faceWidth x
    // faceHeight RGB floats laid out as above, without copying them; the
    // buffer must outlive the map (or the next load).
    void attachFaces(const float* texels, int faceWidth, int faceHeight);

    // YOURS (EnvironmentMap.cpp): the environment's colour in `direction`,
    // of any finite length (from denormals to 1e308): the answer must not
    // depend on the length. A zero, NaN or infinite direction has no face:
    // return any colour, but do not crash or throw.
    Color fetchColor(const Vector3& direction) const;

    // YOURS (EnvironmentMap.cpp): the colour of the face that starts at
    // `addr` at face parameters (u, v) in [0,1] x [0,1].
    // Virtual so the grader can see which face and (u, v) your fetchColor
    // asks for (it answers those calls itself and judges fetchColor as if
    // readTexture were the handout's); define it as usual, without
    // `virtual`, and call it as usual from fetchColor.
    virtual Color readTexture(const float* addr, double u, double v) const;

    // The first texel of face `face` (0..5, e.g. FACE_POS_X).
    const float* faceAddress(int face) const
    {
        return m_Texels + static_cast<std::size_t>(face) * m_FaceWidth * m_FaceHeight * 3;
    }

    int faceWidth() const { return m_FaceWidth; }
    int faceHeight() const { return m_FaceHeight; }

    // The same face numbers, also usable as EnvironmentMap::FACE_POS_X.
    static constexpr int FACE_POS_X = ::FACE_POS_X;
    static constexpr int FACE_NEG_X = ::FACE_NEG_X;
    static constexpr int FACE_POS_Y = ::FACE_POS_Y;
    static constexpr int FACE_NEG_Y = ::FACE_NEG_Y;
    static constexpr int FACE_POS_Z = ::FACE_POS_Z;
    static constexpr int FACE_NEG_Z = ::FACE_NEG_Z;

protected:
    int m_FaceWidth = 0;               // texels per face row
    int m_FaceHeight = 0;              // texel rows per face
    const float* m_Texels = nullptr;   // 6 faces, one above the other (see above)

private:
    std::vector<float> m_OwnTexels;    // the buffer m_Texels points into after a load
    std::string m_LoadError;
};

#endif
