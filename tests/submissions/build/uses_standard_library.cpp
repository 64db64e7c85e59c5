// Build case: a correct solution that also uses much of the standard
// library (none of it is needed): the build's object checks must accept
// every symbol of libc, libm, libstdc++ and libgcc it calls.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <complex>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <mutex>
#include <random>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <typeinfo>
#include <unordered_map>
#include <valarray>
#include <vector>

namespace {

thread_local int tls_counter = 0;
std::mutex guard;

[[maybe_unused]] std::string exercise(double x)
{
    std::lock_guard<std::mutex> lock(guard);
    static std::map<int, std::string> names{{0, "zero"}};   // a guarded static
    std::ostringstream out;
    out << std::setprecision(3) << x << names[0] << std::to_string(std::stoi("7"));
    std::mt19937 rng(42);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    std::complex<double> z(std::sin(x), std::cos(x));
    std::valarray<double> v{1.0, 2.0};
    std::unordered_map<std::string, int> counts{{"a", 1}};
    auto shared = std::make_shared<std::vector<float>>(3, 1.0f);
    std::function<double(double)> f = [](double t) { return std::exp(t) + std::log1p(t); };
    std::atomic<int> a{0};
    a.fetch_add(1);
    ++tls_counter;
    std::thread worker([&a] { a.fetch_add(1); });
    worker.join();
    try {
        throw std::runtime_error(typeid(x).name());
    } catch (const std::exception& e) {
        out << e.what();
    }
    std::regex digits("[0-9]+");
    out << std::regex_search(out.str(), digits) << std::abs(z) << v.sum() << counts.size()
        << shared->size() << f(uniform(rng)) << a.load() << std::filesystem::path("a/b").filename()
        << std::chrono::steady_clock::now().time_since_epoch().count();
    std::cerr << "";
    return out.str();
}

} // namespace

// A correct solution as an idiomatic modern C++ student might write it:
// small value types, constexpr tables, structured bindings, std::clamp.
#include "EnvironmentMap.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

namespace {

struct FaceCoord
{
    int face;
    double u;
    double v;
};

// Where a direction meets the cube: the face and (u, v) of README.md's table.
FaceCoord directionToFace(const Vector3& d)
{
    const double ax = std::abs(d.x), ay = std::abs(d.y), az = std::abs(d.z);
    auto toUnit = [](double s, double m) { return (s / m + 1.0) / 2.0; };
    if (ax >= ay && ax >= az) {
        return d.x > 0 ? FaceCoord{FACE_POS_X, toUnit(d.z, ax), toUnit(d.y, ax)}
                       : FaceCoord{FACE_NEG_X, toUnit(-d.z, ax), toUnit(d.y, ax)};
    }
    if (ay >= az) {
        return d.y > 0 ? FaceCoord{FACE_POS_Y, toUnit(d.x, ay), toUnit(d.z, ay)}
                       : FaceCoord{FACE_NEG_Y, toUnit(d.x, ay), toUnit(-d.z, ay)};
    }
    return d.z > 0 ? FaceCoord{FACE_POS_Z, toUnit(d.x, az), toUnit(-d.y, az)}
                   : FaceCoord{FACE_NEG_Z, toUnit(d.x, az), toUnit(d.y, az)};
}

} // namespace

Color EnvironmentMap::fetchColor(const Vector3& direction) const
{
    const auto [face, u, v] = directionToFace(direction);
    return readTexture(faceAddress(face), u, v);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    const double px = u * m_FaceWidth;
    const double py = v * m_FaceHeight;
    const int ix = static_cast<int>(px);
    const int iy = static_cast<int>(py);
    const double alpha = px - ix;
    const double beta = py - iy;

    const auto texel = [&](int x, int y) -> Color {
        x = std::clamp(x, 0, m_FaceWidth - 1);
        y = std::clamp(y, 0, m_FaceHeight - 1);
        const float* t = addr + 3 * (static_cast<std::ptrdiff_t>(y) * m_FaceWidth + x);
        return {t[0], t[1], t[2]};
    };
    const Color c0 = (1.0 - alpha) * texel(ix, iy) + alpha * texel(ix + 1, iy);
    const Color c1 = (1.0 - alpha) * texel(ix, iy + 1) + alpha * texel(ix + 1, iy + 1);
    return (1.0 - beta) * c0 + beta * c1;
}
