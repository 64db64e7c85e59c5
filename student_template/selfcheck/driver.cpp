// selfcheck/driver.cpp - runs YOUR fetchColor and readTexture on the
// self-check's inputs and writes what they return; selfcheck.py compares
// that with the expected data (selfcheck/data) and scores it.
//
//   selfcheck_driver JOBFILE STATUSFILE
//
// JOBFILE has one command per line, fields separated by tabs:
//   faces  W  H  FILE.f32        six faces from raw float32 (6*H*W*3), see below
//   cross  FILE.hdr              the faces of a vertical-cross .hdr map
//   fetch  IN.f64  OUT.f64 [FIRST COUNT]   fetchColor on n directions (n*3 doubles) -> n*3 doubles
//   texture FACE  IN.f64  OUT.f64 [FIRST COUNT]   readTexture(faceAddress(FACE), u, v) on n (u, v)
//                                 (FIRST COUNT: only those rows of IN)
//   render SCENE.cfg  MAP.hdr  W  H  SPP  OUT.f32   the scene rendered with fetchColor
//                                   in MAP ("-": the scene's own map)
// After each command it appends "done<TAB>index" to STATUSFILE; an exception
// from your code appends "exception<TAB>index<TAB>row<TAB>message" and gives
// NaN for that row. (A file, not stdout: your code may print what it likes.)
// Exit status: 0, or 86 when a command is malformed or a file is missing.
//
// The faces sit in the middle of a larger buffer whose other floats are NaN:
// reading outside the faces (x = -1 or x = W on the first or last face)
// makes the answer NaN, which the report calls an out-of-bounds read.
// Only the C++17 standard library and the provided renderer: builds with
// g++, clang and MSVC.
#include <cstdio>
#include <cstring>
#include <exception>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "EnvironmentMap.h"
#include "envmap.h"

namespace {

const double NaN = std::numeric_limits<double>::quiet_NaN();

bool readFile(const std::string& path, std::vector<char>& bytes)
{
    std::ifstream in(path, std::ios::binary);
    if (!in)
        return false;
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    return true;
}

template <class T>
bool readArray(const std::string& path, std::vector<T>& out)
{
    std::vector<char> bytes;
    if (!readFile(path, bytes) || bytes.size() % sizeof(T) != 0)
        return false;
    out.resize(bytes.size() / sizeof(T));
    if (!bytes.empty())
        std::memcpy(out.data(), bytes.data(), bytes.size());
    return true;
}

// Rows [first, first + count) of rows of `width` values; false when out of range.
bool selectRows(std::vector<double>& values, std::size_t width, const std::vector<std::string>& f, std::size_t at)
{
    if (f.size() == at)
        return values.size() % width == 0;
    if (f.size() != at + 2 || values.size() % width != 0)
        return false;
    const std::size_t first = std::stoul(f[at]), count = std::stoul(f[at + 1]), rows = values.size() / width;
    if (first > rows || count > rows - first)
        return false;
    values = std::vector<double>(values.begin() + first * width, values.begin() + (first + count) * width);
    return true;
}

template <class T>
bool writeArray(const std::string& path, const std::vector<T>& data)
{
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(data.data()), static_cast<std::streamsize>(data.size() * sizeof(T)));
    return static_cast<bool>(out);
}

std::vector<std::string> splitTabs(const std::string& line)
{
    std::vector<std::string> out;
    std::string field;
    std::istringstream in(line);
    while (std::getline(in, field, '\t'))
        out.push_back(field);
    return out;
}

struct Driver {
    EnvironmentMap map;
    std::vector<float> guarded;   // NaN, the six faces, NaN
    std::ofstream status;
    int index = 0;
    int exceptions = 0;            // reported in this command (a few are enough)

    void exception(std::size_t row, const char* what)
    {
        std::string text = what ? what : "";
        for (char& c : text)
            if (c == '\t' || c == '\n' || c == '\r')
                c = ' ';
        if (++exceptions <= 5)
            status << "exception\t" << index << '\t' << row << '\t' << text.substr(0, 200) << std::endl;
    }

    bool faces(int w, int h, const std::string& path)
    {
        std::vector<float> texels;
        const std::size_t count = static_cast<std::size_t>(6) * w * h * 3;
        if (w <= 0 || h <= 0 || !readArray(path, texels) || texels.size() != count)
            return false;
        const std::size_t pad = static_cast<std::size_t>(w) * h * 3 + 3 * static_cast<std::size_t>(w) + 64;
        guarded.assign(count + 2 * pad, std::numeric_limits<float>::quiet_NaN());
        std::memcpy(guarded.data() + pad, texels.data(), count * sizeof(float));
        map.attachFaces(guarded.data() + pad, w, h);
        return true;
    }

    bool fetch(const std::vector<std::string>& f)
    {
        std::vector<double> dirs;
        if (!readArray(f[1], dirs) || !selectRows(dirs, 3, f, 3))
            return false;
        const std::string& out = f[2];
        std::vector<double> rgb(dirs.size(), NaN);
        for (std::size_t i = 0; i < dirs.size() / 3; ++i) {
            try {
                const Color c = map.fetchColor(Vector3(dirs[3 * i], dirs[3 * i + 1], dirs[3 * i + 2]));
                rgb[3 * i] = c.r;
                rgb[3 * i + 1] = c.g;
                rgb[3 * i + 2] = c.b;
            } catch (const std::exception& e) {
                exception(i, e.what());
            } catch (...) {
                exception(i, "an exception that is not a std::exception");
            }
        }
        return writeArray(out, rgb);
    }

    bool texture(const std::vector<std::string>& f)
    {
        std::vector<double> uv;
        const int face = std::stoi(f[1]);
        if (face < 0 || face > 5 || !readArray(f[2], uv) || !selectRows(uv, 2, f, 4))
            return false;
        const std::string& out = f[3];
        std::vector<double> rgb(uv.size() / 2 * 3, NaN);
        const float* addr = map.faceAddress(face);
        for (std::size_t i = 0; i < uv.size() / 2; ++i) {
            try {
                const Color c = map.readTexture(addr, uv[2 * i], uv[2 * i + 1]);
                rgb[3 * i] = c.r;
                rgb[3 * i + 1] = c.g;
                rgb[3 * i + 2] = c.b;
            } catch (const std::exception& e) {
                exception(i, e.what());
            } catch (...) {
                exception(i, "an exception that is not a std::exception");
            }
        }
        return writeArray(out, rgb);
    }

    static int lookup(void* context, const double* dirs, std::size_t n, double* rgbOut)
    {
        Driver& self = *static_cast<Driver*>(context);
        for (std::size_t i = 0; i < n; ++i) {
            Color c(NaN, NaN, NaN);
            try {
                c = self.map.fetchColor(Vector3(dirs[3 * i], dirs[3 * i + 1], dirs[3 * i + 2]));
            } catch (const std::exception& e) {
                self.exception(i, e.what());
            } catch (...) {
                self.exception(i, "an exception that is not a std::exception");
            }
            // The picture's NaN pixels count as black, as in the grader.
            rgbOut[3 * i] = c.r == c.r ? c.r : 0.0;
            rgbOut[3 * i + 1] = c.g == c.g ? c.g : 0.0;
            rgbOut[3 * i + 2] = c.b == c.b ? c.b : 0.0;
        }
        return 0;
    }

    bool render(const std::string& scenePath, const std::string& mapPath, int w, int h, int spp, const std::string& out)
    {
        em_error error = {};
        em_scene* scene = nullptr;
        if (em_scene_load(scenePath.c_str(), &scene, &error) != EM_OK) {
            std::cerr << error.message << std::endl;
            return false;
        }
        em_scene_set_resolution(scene, w, h);
        em_scene_set_samples(scene, spp);
        bool ok = map.loadFromCrossHDR(mapPath == "-" ? em_scene_environment_path(scene) : mapPath.c_str());
        em_image image = {};
        if (!ok)
            std::cerr << map.loadError() << std::endl;
        else if (em_render(scene, &Driver::lookup, this, &image, &error) != EM_OK) {
            std::cerr << error.message << std::endl;
            ok = false;
        }
        em_scene_free(scene);
        if (ok) {
            const std::size_t n = static_cast<std::size_t>(image.width) * image.height * 3;
            ok = writeArray(out, std::vector<float>(image.rgb, image.rgb + n));
        }
        em_image_free(&image);
        return ok;
    }

    bool run(const std::vector<std::string>& f)
    {
        if (f.empty())
            return true;
        const std::string& cmd = f[0];
        if (cmd == "faces" && f.size() == 4)
            return faces(std::stoi(f[1]), std::stoi(f[2]), f[3]);
        if (cmd == "cross" && f.size() == 2) {
            if (!map.loadFromCrossHDR(f[1].c_str())) {
                std::cerr << map.loadError() << std::endl;
                return false;
            }
            return true;
        }
        if (cmd == "fetch" && (f.size() == 3 || f.size() == 5))
            return fetch(f);
        if (cmd == "texture" && (f.size() == 4 || f.size() == 6))
            return texture(f);
        if (cmd == "render" && f.size() == 7)
            return render(f[1], f[2], std::stoi(f[3]), std::stoi(f[4]), std::stoi(f[5]), f[6]);
        std::cerr << "selfcheck driver: bad command: " << cmd << std::endl;
        return false;
    }
};

} // namespace

int main(int argc, char** argv)
{
    if (argc != 3) {
        std::cerr << "usage: " << argv[0] << " JOBFILE STATUSFILE" << std::endl;
        return 86;
    }
    std::ifstream jobs(argv[1]);
    static Driver driver;   // static: the map's buffer outlives every call
    driver.status.open(argv[2], std::ios::out | std::ios::trunc);
    if (!jobs || !driver.status) {
        std::cerr << "cannot read " << argv[1] << " or write " << argv[2] << std::endl;
        return 86;
    }
    std::string line;
    while (std::getline(jobs, line)) {
        if (!line.empty() && line.back() == '\r')
            line.pop_back();
        bool ok = false;
        try {
            ok = driver.run(splitTabs(line));
        } catch (const std::exception& e) {
            driver.exception(0, e.what());
            std::cerr << "selfcheck driver: " << e.what() << std::endl;
        }
        if (!ok) {
            std::cerr << "selfcheck driver: command " << driver.index << " failed: " << line << std::endl;
            return 86;
        }
        driver.status << "done\t" << driver.index << std::endl;
        ++driver.index;
        driver.exceptions = 0;
    }
    return 0;
}
