// shim.cpp - submission_abi.h over a student's EnvironmentMap.
//
// Compiled by grader/build/common.py with the template's headers into the
// submission's shared library. No C++ exception crosses the C boundary:
// each entry point catches everything and reports it as SUB_ERR_EXCEPTION
// with the exception's message.
#include "submission_abi.h"

#include <cstdint>
#include <cstring>
#include <exception>

#include "EnvironmentMap.h"

namespace {

void setMessage(char* message, std::size_t size, const char* text)
{
    if (message == nullptr || size == 0)
        return;
    std::strncpy(message, text, size - 1);
    message[size - 1] = '\0';
}

// Run `body`; turn any exception into SUB_ERR_EXCEPTION and its message.
template <class Body>
int guarded(char* message, std::size_t size, Body body)
{
    try {
        return body();
    } catch (const std::exception& e) {
        setMessage(message, size, e.what());
    } catch (...) {
        setMessage(message, size, "unknown exception");
    }
    return SUB_ERR_EXCEPTION;
}

EnvironmentMap* asMap(void* map) { return static_cast<EnvironmentMap*>(map); }

// The student's fetchColor over the same texels, with a readTexture that
// logs each call and answers with the grader's tag for it: what fetchColor
// asks for is seen exactly, and whether it returns what it read. No texel is
// read here (no lookup is compiled into a submission's library).
class RecordingMap final : public EnvironmentMap
{
public:
    RecordingMap(const EnvironmentMap& real, const double* tags) : m_Tags(tags)
    {
        attachFaces(real.faceAddress(0), real.faceWidth(), real.faceHeight());
    }

    // Starts the log of one fetchColor call.
    void begin(sub_texture_call* calls)
    {
        m_Calls = calls;
        m_Count = 0;
    }
    std::size_t count() const { return m_Count; }

    Color readTexture(const float* addr, double u, double v) const override
    {
        const std::size_t k = m_Count++;
        if (k < SUB_RECORDED_CALLS) {
            // Distances as integers: the address may point anywhere.
            const std::ptrdiff_t bytes = static_cast<std::ptrdiff_t>(reinterpret_cast<std::uintptr_t>(addr)
                                                                     - reinterpret_cast<std::uintptr_t>(m_Texels));
            const std::ptrdiff_t faceBytes = static_cast<std::ptrdiff_t>(m_FaceWidth) * m_FaceHeight * 3
                                             * static_cast<std::ptrdiff_t>(sizeof(float));
            const bool start = faceBytes > 0 && bytes % faceBytes == 0 && bytes >= 0 && bytes / faceBytes < FACE_COUNT;
            m_Calls[k] = {start ? static_cast<double>(bytes / faceBytes) : -1.0,
                          static_cast<double>(bytes) / static_cast<double>(sizeof(float)), u, v};
        }
        const double* tag = m_Tags + 3 * (k % SUB_RECORDED_CALLS);
        return Color(tag[0], tag[1], tag[2]);
    }

private:
    const double* m_Tags;
    sub_texture_call* m_Calls = nullptr;
    mutable std::size_t m_Count = 0;
};

} // namespace

extern "C" {

int sub_abi_version(void) { return SUB_ABI_VERSION; }

void* sub_create(char* message, size_t message_size)
{
    void* map = nullptr;
    guarded(message, message_size, [&] {
        map = new EnvironmentMap();
        return SUB_OK;
    });
    return map;
}

void sub_destroy(void* map)
{
    // The destructor is ours (the template's), so it does not throw.
    delete asMap(map);
}

int sub_set_faces(void* map, const float* texels, int w, int h, char* message, size_t message_size)
{
    if (map == nullptr || texels == nullptr || w <= 0 || h <= 0) {
        setMessage(message, message_size, "sub_set_faces: NULL map or texels, or a face size <= 0");
        return SUB_ERR_ARGUMENT;
    }
    return guarded(message, message_size, [&] {
        asMap(map)->attachFaces(texels, w, h);
        return SUB_OK;
    });
}

int sub_fetch_batch(void* map, const double* dirs, size_t n, double* rgb, char* message,
                    size_t message_size)
{
    if (map == nullptr || (n > 0 && (dirs == nullptr || rgb == nullptr))) {
        setMessage(message, message_size, "sub_fetch_batch: NULL argument");
        return SUB_ERR_ARGUMENT;
    }
    return guarded(message, message_size, [&] {
        const EnvironmentMap& env = *asMap(map);
        for (size_t i = 0; i < n; ++i) {
            const Color c = env.fetchColor(Vector3(dirs[3 * i], dirs[3 * i + 1], dirs[3 * i + 2]));
            rgb[3 * i] = c.r;
            rgb[3 * i + 1] = c.g;
            rgb[3 * i + 2] = c.b;
        }
        return SUB_OK;
    });
}

int sub_read_texture_batch(void* map, const float* addr, const double* uv, size_t n, double* rgb,
                           char* message, size_t message_size)
{
    if (map == nullptr || (n > 0 && (addr == nullptr || uv == nullptr || rgb == nullptr))) {
        setMessage(message, message_size, "sub_read_texture_batch: NULL argument");
        return SUB_ERR_ARGUMENT;
    }
    return guarded(message, message_size, [&] {
        const EnvironmentMap& env = *asMap(map);
        for (size_t i = 0; i < n; ++i) {
            const Color c = env.readTexture(addr, uv[2 * i], uv[2 * i + 1]);
            rgb[3 * i] = c.r;
            rgb[3 * i + 1] = c.g;
            rgb[3 * i + 2] = c.b;
        }
        return SUB_OK;
    });
}

int sub_record_fetch_batch(void* map, const double* dirs, size_t n, const double* tags, double* rgb,
                           double* counts, sub_texture_call* calls, char* message, size_t message_size)
{
    if (map == nullptr || tags == nullptr
        || (n > 0 && (dirs == nullptr || rgb == nullptr || counts == nullptr || calls == nullptr))) {
        setMessage(message, message_size, "sub_record_fetch_batch: NULL argument");
        return SUB_ERR_ARGUMENT;
    }
    return guarded(message, message_size, [&] {
        RecordingMap recorder(*asMap(map), tags);
        const EnvironmentMap& env = recorder;
        for (size_t i = 0; i < n; ++i) {
            recorder.begin(calls + SUB_RECORDED_CALLS * i);
            const Color c = env.fetchColor(Vector3(dirs[3 * i], dirs[3 * i + 1], dirs[3 * i + 2]));
            rgb[3 * i] = c.r;
            rgb[3 * i + 1] = c.g;
            rgb[3 * i + 2] = c.b;
            counts[i] = static_cast<double>(recorder.count());
        }
        return SUB_OK;
    });
}

int sub_load_cross(void* map, const char* path, char* message, size_t message_size)
{
    if (map == nullptr || path == nullptr) {
        setMessage(message, message_size, "sub_load_cross: NULL argument");
        return SUB_ERR_ARGUMENT;
    }
    return guarded(message, message_size, [&] {
        EnvironmentMap& env = *asMap(map);
        if (env.loadFromCrossHDR(path))
            return 1;
        setMessage(message, message_size, env.loadError().c_str());
        return 0;
    });
}

} // extern "C"
