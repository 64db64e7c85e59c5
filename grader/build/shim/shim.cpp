// shim.cpp - submission_abi.h over a student's EnvironmentMap.
//
// Compiled by grader/build/common.py with the template's headers into the
// submission's shared library. No C++ exception crosses the C boundary:
// each entry point catches everything and reports it as SUB_ERR_EXCEPTION
// with the exception's message.
#include "submission_abi.h"

#include <cstdint>
#include <cmath>
#include <cstring>
#include <exception>
#include <limits>

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


// The map every entry point uses: its readTexture is the student's until a
// recording is on (sub_record_fetch_batch); then each call fetchColor makes
// is logged and answered with the grader's tag for it (no texel is read here:
// no lookup is compiled into a submission's library), or, recording without
// tags, with the student's own readTexture. One class throughout, so the
// map's type (typeid, vtable) says nothing about being recorded.
class ObservedMap final : public EnvironmentMap
{
public:
    // Starts (calls != nullptr) or stops the log of one fetchColor call.
    void record(sub_texture_call* calls, const double* tags)
    {
        m_Calls = calls;
        m_Tags = tags;
        m_Count = 0;
        m_Answers[0] = Color();
    }
    std::size_t count() const { return m_Count; }
    // Which logged call's answer `c` is (-1: none): each channel bit for bit,
    // or that answer rounded to float, as a fetchColor that keeps colours in
    // float returns what it was given (the tags are exact in float).
    int returned(const Color& c) const
    {
        for (std::size_t k = 0; k < m_Count && k < SUB_RECORDED_CALLS; ++k)
            if (same(m_Answers[k].r, c.r) && same(m_Answers[k].g, c.g) && same(m_Answers[k].b, c.b))
                return static_cast<int>(k);
        return -1;
    }
    static bool same(double answer, double got)
    {
        if (std::memcmp(&answer, &got, sizeof got) == 0)
            return true;
        // A double beyond float's range has no float to round to (the
        // conversion is undefined): only the bits count there.
        if (!(std::fabs(answer) <= std::numeric_limits<float>::max()))
            return false;
        const double through_float = static_cast<double>(static_cast<float>(answer));
        return std::memcmp(&through_float, &got, sizeof got) == 0;
    }

    Color readTexture(const float* addr, double u, double v) const override
    {
        if (m_Calls == nullptr)
            return EnvironmentMap::readTexture(addr, u, v);
        const std::size_t k = m_Count++;
        // Distances as integers: the address may point anywhere.
        const std::ptrdiff_t bytes = static_cast<std::ptrdiff_t>(reinterpret_cast<std::uintptr_t>(addr)
                                                                 - reinterpret_cast<std::uintptr_t>(m_Texels));
        const sub_texture_call call = {-1.0, static_cast<double>(bytes) / static_cast<double>(sizeof(float)), u, v};
        // The same question gets the same tag: a fetchColor that asks twice
        // and averages returns the tag it was given (the student's own
        // readTexture, when it answers, is asked every time).
        const int earlier = m_Tags != nullptr ? asked(call, k) : -1;
        const Color answer = earlier >= 0 ? m_Answers[earlier]
                           : m_Tags != nullptr ? tag(k) : EnvironmentMap::readTexture(addr, u, v);
        if (k < SUB_RECORDED_CALLS) {
            const std::ptrdiff_t faceBytes = static_cast<std::ptrdiff_t>(m_FaceWidth) * m_FaceHeight * 3
                                             * static_cast<std::ptrdiff_t>(sizeof(float));
            const bool start = faceBytes > 0 && bytes % faceBytes == 0 && bytes >= 0 && bytes / faceBytes < FACE_COUNT;
            m_Calls[k] = call;
            m_Calls[k].face = start ? static_cast<double>(bytes / faceBytes) : -1.0;
            m_Answers[k] = answer;
        }
        return answer;
    }

private:
    // The first logged call of this fetchColor with the same address, u and v
    // (bit for bit), or -1.
    int asked(const sub_texture_call& call, std::size_t k) const
    {
        for (std::size_t j = 0; j < k && j < SUB_RECORDED_CALLS; ++j)
            if (m_Calls[j].offset == call.offset && std::memcmp(&m_Calls[j].u, &call.u, sizeof call.u) == 0
                && std::memcmp(&m_Calls[j].v, &call.v, sizeof call.v) == 0)
                return static_cast<int>(j);
        return -1;
    }

    Color tag(std::size_t k) const
    {
        const double* t = m_Tags + 3 * (k % SUB_RECORDED_CALLS);
        return Color(t[0], t[1], t[2]);
    }

    sub_texture_call* m_Calls = nullptr;
    const double* m_Tags = nullptr;
    mutable std::size_t m_Count = 0;
    mutable Color m_Answers[SUB_RECORDED_CALLS];
};

ObservedMap* asObserved(void* map) { return static_cast<ObservedMap*>(map); }

// Every other entry point first ends a recording a fault jumped out of.
EnvironmentMap* asMap(void* map)
{
    asObserved(map)->record(nullptr, nullptr);
    return asObserved(map);
}

} // namespace

extern "C" {

int sub_abi_version(void) { return SUB_ABI_VERSION; }

void* sub_create(char* message, size_t message_size)
{
    void* map = nullptr;
    guarded(message, message_size, [&] {
        map = new ObservedMap();
        return SUB_OK;
    });
    return map;
}

void sub_destroy(void* map)
{
    // The destructor is ours (the template's), so it does not throw.
    delete asObserved(map);
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
                           double* summary, sub_texture_call* calls, char* message, size_t message_size)
{
    if (map == nullptr || (n > 0 && (dirs == nullptr || rgb == nullptr || summary == nullptr || calls == nullptr))) {
        setMessage(message, message_size, "sub_record_fetch_batch: NULL argument");
        return SUB_ERR_ARGUMENT;
    }
    ObservedMap& observed = *asObserved(map);
    const int status = guarded(message, message_size, [&] {
        const EnvironmentMap& env = observed;
        for (size_t i = 0; i < n; ++i) {
            observed.record(calls + SUB_RECORDED_CALLS * i, tags);
            const Color c = env.fetchColor(Vector3(dirs[3 * i], dirs[3 * i + 1], dirs[3 * i + 2]));
            rgb[3 * i] = c.r;
            rgb[3 * i + 1] = c.g;
            rgb[3 * i + 2] = c.b;
            summary[2 * i] = static_cast<double>(observed.count());
            summary[2 * i + 1] = static_cast<double>(observed.returned(c));
        }
        return SUB_OK;
    });
    observed.record(nullptr, nullptr);
    return status;
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
