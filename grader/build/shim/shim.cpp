// shim.cpp - submission_abi.h over a student's EnvironmentMap.
//
// Compiled by grader/build/common.py with the template's headers into the
// submission's shared library. No C++ exception crosses the C boundary:
// each entry point catches everything and reports it as SUB_ERR_EXCEPTION
// with the exception's message.
#include "submission_abi.h"

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
