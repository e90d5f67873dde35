// Tries the llvmpipe yardstick by hand: draws an N×N heightfield (~2·(N−1)² triangles)
// at 1920×1080, prints the draw times, and checks the depth it read back.
//
//   ./build/reference/gl_reference_try [N=709] [threads=2] [--reversed] [--again THREADS]
//
// --reversed  draws with a reversed-Z [0, 1] projection (near → 1, far → 0).
// --again T   draws a second time in the same process with T threads, and prints the most
//             threads the process had during each call besides this program's own (llvmpipe's
//             rasterizer threads show there), to see whether LP_NUM_THREADS took effect again.
#include "zcheck/gl_reference.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

namespace {

using Mat4 = std::array<double, 16>; // column-major: element (row r, column c) at [4c + r]
using Vec3 = std::array<double, 3>;

double& at(Mat4& m, int row, int column)
{
    return m[4 * column + row];
}

Mat4 multiply(const Mat4& a, const Mat4& b)
{
    Mat4 product{};
    for (int row = 0; row < 4; ++row)
        for (int column = 0; column < 4; ++column)
            for (int k = 0; k < 4; ++k) product[4 * column + row] += a[4 * k + row] * b[4 * column + k];
    return product;
}

Vec3 subtract(const Vec3& a, const Vec3& b)
{
    return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
Vec3 cross(const Vec3& a, const Vec3& b)
{
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const Vec3& a, const Vec3& b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
Vec3 normalize(const Vec3& v)
{
    const double length = std::sqrt(dot(v, v));
    return {v[0] / length, v[1] / length, v[2] / length};
}

// gluLookAt: rows s, u, −f, then a translation by −eye.
Mat4 lookAt(const Vec3& eye, const Vec3& center, const Vec3& up)
{
    const Vec3 f = normalize(subtract(center, eye));
    const Vec3 s = normalize(cross(f, up));
    const Vec3 u = cross(s, f);
    Mat4 viewFromWorld{};
    for (int column = 0; column < 3; ++column) {
        at(viewFromWorld, 0, column) = s[column];
        at(viewFromWorld, 1, column) = u[column];
        at(viewFromWorld, 2, column) = -f[column];
    }
    at(viewFromWorld, 0, 3) = -dot(s, eye);
    at(viewFromWorld, 1, 3) = -dot(u, eye);
    at(viewFromWorld, 2, 3) = dot(f, eye);
    at(viewFromWorld, 3, 3) = 1.0;
    return viewFromWorld;
}

// gluPerspective: OpenGL clip space, −w ≤ z ≤ w with near → −1.
Mat4 perspective(double fovyRadians, double aspect, double near, double far)
{
    const double focal = 1.0 / std::tan(fovyRadians / 2.0);
    Mat4 clipFromView{};
    at(clipFromView, 0, 0) = focal / aspect;
    at(clipFromView, 1, 1) = focal;
    at(clipFromView, 2, 2) = (far + near) / (near - far);
    at(clipFromView, 2, 3) = 2.0 * far * near / (near - far);
    at(clipFromView, 3, 2) = -1.0;
    return clipFromView;
}

// Reversed-Z [0, 1]: z_clip / w_clip = n(f/d − 1)/(f − n) for eye distance d = −z_view,
// so near → 1 and far → 0.
Mat4 reversedPerspective(double fovyRadians, double aspect, double near, double far)
{
    Mat4 clipFromView = perspective(fovyRadians, aspect, near, far);
    at(clipFromView, 2, 2) = near / (far - near);
    at(clipFromView, 2, 3) = far * near / (far - near);
    return clipFromView;
}

// Threads of this process now (llvmpipe's rasterizer threads live while its context does).
int processThreadCount()
{
    std::ifstream status("/proc/self/status");
    for (std::string line; std::getline(status, line);)
        if (line.rfind("Threads:", 0) == 0) return std::atoi(line.c_str() + 8);
    return -1;
}

double median(std::vector<double> values)
{
    std::sort(values.begin(), values.end());
    const std::size_t n = values.size();
    return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

} // namespace

int main(int argc, char** argv)
{
    int gridSize = 709;
    int threads = 2;
    bool reversedZ = false;
    int againThreads = -1;
    int positional = 0;
    for (int i = 1; i < argc; ++i) {
        if (std::strcmp(argv[i], "--reversed") == 0) {
            reversedZ = true;
        } else if (std::strcmp(argv[i], "--again") == 0 && i + 1 < argc) {
            againThreads = std::atoi(argv[++i]);
        } else if (positional == 0) {
            gridSize = std::atoi(argv[i]), ++positional;
        } else if (positional == 1) {
            threads = std::atoi(argv[i]), ++positional;
        } else {
            std::fprintf(stderr, "usage: %s [N] [threads] [--reversed] [--again THREADS]\n", argv[0]);
            return 2;
        }
    }
    if (gridSize < 2) {
        std::fprintf(stderr, "N must be at least 2\n");
        return 2;
    }

    // Heightfield over x, z ∈ [−1, 1].
    const auto n = static_cast<std::size_t>(gridSize);
    std::vector<float> positions;
    positions.reserve(3 * n * n);
    for (std::size_t row = 0; row < n; ++row) {
        for (std::size_t column = 0; column < n; ++column) {
            const double x = -1.0 + 2.0 * static_cast<double>(column) / static_cast<double>(n - 1);
            const double z = -1.0 + 2.0 * static_cast<double>(row) / static_cast<double>(n - 1);
            positions.push_back(static_cast<float>(x));
            positions.push_back(static_cast<float>(0.02 * std::sin(7.0 * x) * std::cos(5.0 * z)));
            positions.push_back(static_cast<float>(z));
        }
    }
    std::vector<std::uint32_t> indices;
    indices.reserve(6 * (n - 1) * (n - 1));
    for (std::size_t row = 0; row + 1 < n; ++row) {
        for (std::size_t column = 0; column + 1 < n; ++column) {
            const auto v00 = static_cast<std::uint32_t>(row * n + column);
            const auto v01 = v00 + 1;
            const auto v10 = static_cast<std::uint32_t>(v00 + n);
            const auto v11 = v10 + 1;
            indices.insert(indices.end(), {v00, v10, v01, v01, v10, v11});
        }
    }

    constexpr int kWidth = 1920, kHeight = 1080;
    constexpr double kPi = 3.14159265358979323846;
    const double fovy = 60.0 * kPi / 180.0, aspect = double(kWidth) / kHeight, near = 0.01, far = 10.0;
    const Vec3 eye{0.0, 0.6, -0.15};
    const Mat4 viewFromWorld = lookAt(eye, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0});
    const Mat4 clipFromView =
        reversedZ ? reversedPerspective(fovy, aspect, near, far) : perspective(fovy, aspect, near, far);

    zcheck::reference::GlDepthInput input;
    input.positions = positions.data();
    input.vertexCount = n * n;
    input.indices = indices.data();
    input.triangleCount = indices.size() / 3;
    input.clipFromWorld = multiply(clipFromView, viewFromWorld);
    input.width = kWidth;
    input.height = kHeight;
    input.reversedZ = reversedZ;
    input.threads = threads;

    // The centre ray runs along the view axis to the origin, where the surface is y = 0
    // (x = 0 is a grid line): the expected depth follows from the eye distance alone.
    const double eyeDistance = std::sqrt(dot(eye, eye));
    const double expectedCentreDepth =
        reversedZ ? near * (far / eyeDistance - 1.0) / (far - near)
                  : (far + near) / (2.0 * (far - near)) - far * near / ((far - near) * eyeDistance) + 0.5;
    const float clearedDepth = reversedZ ? 0.0f : 1.0f;

    std::printf("%zu triangles, %dx%d, %s depth\n", input.triangleCount, kWidth, kHeight,
                reversedZ ? "reversed-Z [0,1]" : "standard [-1,1]");
    bool ok = true;
    for (const int drawThreads : {threads, againThreads}) {
        if (drawThreads < 0) continue;
        input.threads = drawThreads;
        // With --again, a sampler thread records the peak thread count during the call.
        std::atomic<bool> drawing{true};
        std::atomic<int> peakThreads{0};
        std::thread sampler;
        if (againThreads >= 0) {
            sampler = std::thread([&] {
                while (drawing) {
                    peakThreads = std::max(peakThreads.load(), processThreadCount());
                    std::this_thread::sleep_for(std::chrono::milliseconds(5));
                }
            });
        }
        zcheck::reference::GlDepthTiming timing;
        try {
            timing = zcheck::reference::timeGlDepthDraw(input, 5);
        } catch (const std::exception& error) {
            std::fprintf(stderr, "error: %s\n", error.what());
            drawing = false;
            if (sampler.joinable()) sampler.join();
            return 1;
        }
        drawing = false;
        if (sampler.joinable()) sampler.join();
        std::printf("\nLP_NUM_THREADS=%d, renderer: %s\n", drawThreads, timing.renderer.c_str());
        for (std::size_t i = 0; i < timing.drawMs.size(); ++i)
            std::printf("  draw %zu: %.2f ms\n", i, timing.drawMs[i]);
        std::printf("  median: %.2f ms\n", median(timing.drawMs));
        for (std::size_t i = 0; i < timing.coldDrawMs.size(); ++i)
            std::printf("  draw into a new depth buffer %zu: %.2f ms\n", i, timing.coldDrawMs[i]);
        const bool timedEach = timing.drawMs.size() == 5 && timing.coldDrawMs.size() == 5 &&
                               std::all_of(timing.coldDrawMs.begin(), timing.coldDrawMs.end(), [](double ms) { return ms > 0; });

        const auto covered =
            std::count_if(timing.depth.begin(), timing.depth.end(), [&](float depth) { return depth != clearedDepth; });
        const double coverage = double(covered) / double(timing.depth.size());
        const float centreDepth = timing.depth[std::size_t(kHeight / 2) * kWidth + kWidth / 2];
        const double centreError = std::abs(centreDepth - expectedCentreDepth);
        std::printf("  covered: %.4f%% of pixels\n", 100.0 * coverage);
        std::printf("  centre depth %.6f, expected %.6f (eye distance %.4f), |error| %.2e\n", centreDepth,
                    expectedCentreDepth, eyeDistance, centreError);
        if (againThreads >= 0)
            std::printf("  peak threads besides main and sampler: %d (after the call: %d)\n", peakThreads.load() - 2,
                        processThreadCount() - 1);
        ok = ok && timedEach && coverage > 0.999 && centreError < 1e-3;
    }
    std::printf("\n%s\n", ok ? "OK" : "FAILED");
    return ok ? 0 : 1;
}
