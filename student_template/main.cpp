// main.cpp - render a scene with YOUR fetchColor and write the picture.
//
//   ./envmap [scene.cfg [output-stem]]      (defaults: envmap_test.cfg, out)
//
// writes <stem>.hdr (linear radiance) and <stem>.png (for viewing: each
// channel clamped to [0, 1], then encoded with the sRGB curve). The ray
// tracer is the reference one (renderer/src), so your picture is made
// exactly as the grader makes it; only the environment lookup is yours.
//
// The renderer hands the environment lookups over in batches; each batch is
// split over every core (std::thread), so fetchColor must not change shared
// state (it is const: it cannot, unless you add globals).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <string>
#include <thread>
#include <vector>

#include "EnvironmentMap.h"
#include "PngWriter.h"
#include "envmap.h"

namespace {

void fetchRange(const EnvironmentMap& map, const double* dirs, std::size_t first, std::size_t last, double* rgbOut)
{
    for (std::size_t i = first; i < last; ++i) {
        const Color c = map.fetchColor(Vector3(dirs[3 * i], dirs[3 * i + 1], dirs[3 * i + 2]));
        rgbOut[3 * i] = c.r;
        rgbOut[3 * i + 1] = c.g;
        rgbOut[3 * i + 2] = c.b;
    }
}

// The renderer asks for the environment colour of a batch of directions:
// one slice of the batch per core. An exception never crosses the C
// renderer: it is printed, and the renderer is told the lookup failed.
int lookupWithFetchColor(void* context, const double* dirs, std::size_t n, double* rgbOut)
{
    const EnvironmentMap& map = *static_cast<const EnvironmentMap*>(context);
    const std::size_t cores = std::max(1u, std::thread::hardware_concurrency());
    const std::size_t threads = std::max<std::size_t>(1, std::min<std::size_t>(cores, n / 1024));
    std::vector<std::thread> pool;
    std::vector<std::exception_ptr> errors(threads);
    const std::size_t slice = (n + threads - 1) / threads;
    for (std::size_t t = 0; t < threads; ++t) {
        const std::size_t first = std::min(n, t * slice), last = std::min(n, first + slice);
        pool.emplace_back([&, t, first, last] {
            try {
                fetchRange(map, dirs, first, last, rgbOut);
            } catch (...) {
                errors[t] = std::current_exception();
            }
        });
    }
    for (std::thread& th : pool)
        th.join();
    for (const std::exception_ptr& e : errors) {
        if (!e)
            continue;
        try {
            std::rethrow_exception(e);
        } catch (const std::exception& x) {
            std::fprintf(stderr, "fetchColor threw an exception: %s\n", x.what());
        } catch (...) {
            std::fprintf(stderr, "fetchColor threw an exception\n");
        }
        return 1;
    }
    return 0;
}

// Linear radiance -> 8-bit sRGB: clamp to [0, 1], then the sRGB curve.
unsigned char toSrgb8(float linear)
{
    double c = linear > 0.0f ? (linear < 1.0f ? linear : 1.0) : 0.0; // NaN -> 0
    c = c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055;
    return static_cast<unsigned char>(c * 255.0 + 0.5);
}

bool writeToneMappedPng(const std::string& path, const em_image& image)
{
    const std::size_t count = static_cast<std::size_t>(image.width) * image.height * 3;
    std::vector<unsigned char> rgb(count);
    for (std::size_t i = 0; i < count; ++i)
        rgb[i] = toSrgb8(image.rgb[i]);
    return writePng(path.c_str(), image.width, image.height, rgb.data());
}

int render(const char* scenePath, const std::string& stem)
{
    em_error error = {};
    em_scene* scene = nullptr;
    if (em_scene_load(scenePath, &scene, &error) != EM_OK) {
        std::fprintf(stderr, "%s\n", error.message);
        return 1;
    }
    EnvironmentMap map;
    const char* mapPath = em_scene_environment_path(scene);
    if (!map.loadFromCrossHDR(mapPath)) {
        std::fprintf(stderr, "%s\n", map.loadError().c_str());
        em_scene_free(scene);
        return 1;
    }
    std::printf("rendering %s (%d x %d) with the environment %s\n", scenePath,
                em_scene_width(scene), em_scene_height(scene), mapPath);

    em_image image = {};
    const int status = em_render(scene, lookupWithFetchColor, &map, &image, &error);
    em_scene_free(scene);
    if (status != EM_OK) {
        std::fprintf(stderr, "%s\n", error.message);
        return 1;
    }
    int exitStatus = 0;
    const std::string hdrPath = stem + ".hdr", pngPath = stem + ".png";
    if (em_rgbe_write(hdrPath.c_str(), &image, &error) != EM_OK) {
        std::fprintf(stderr, "%s\n", error.message);
        exitStatus = 1;
    }
    if (!writeToneMappedPng(pngPath, image)) {
        std::fprintf(stderr, "%s: cannot write the file\n", pngPath.c_str());
        exitStatus = 1;
    }
    em_image_free(&image);
    if (exitStatus == 0)
        std::printf("wrote %s and %s\n", hdrPath.c_str(), pngPath.c_str());
    return exitStatus;
}

} // namespace

int main(int argc, char** argv)
{
    if (argc > 3 || (argc > 1 && argv[1][0] == '-')) {
        std::fprintf(stderr, "usage: %s [scene.cfg [output-stem]]\n", argv[0]);
        return 2;
    }
    const char* scenePath = argc > 1 ? argv[1] : "envmap_test.cfg";
    const std::string stem = argc > 2 ? argv[2] : "out";
    try {
        return render(scenePath, stem);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "exception: %s\n", e.what());
    } catch (...) {
        std::fprintf(stderr, "unknown exception\n");
    }
    return 1;
}
