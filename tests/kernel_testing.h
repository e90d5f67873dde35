#pragma once
// For the tests that run a route's forms (zcheck/kernel_form.h: baseline, avx2, avx512) and
// compare them bit for bit: a scene that exercises them and the switch between them.
#include "zcheck/camera.h"
#include "zcheck/kernel_form.h"
#include "zcheck/scene.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <random>
#include <string>
#include <vector>

namespace zcheck::testing {

// 3000 triangles from sub-pixel slivers to ones spanning several 64×64 tiles of a 203×141
// image through kernelCamera, with exact duplicates under other ids and both windings.
// `inside`: all between its near and far planes, anywhere in the view and past its edges;
// otherwise most cross the near or far plane.
inline Scene triangleSoup(bool inside, std::uint32_t seed)
{
    std::mt19937 random(seed);
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f), depth(-12.0f, -0.2f), depthInside(-7.0f, -1.5f);
    Scene scene;
    scene.name = "triangle soup";
    for (int k = 0; k < 3000; ++k) {
        const float size = std::pow(10.0f, unit(random) * 1.5f - 1.0f);  // 0.003 to 3 (image ≈ 2 wide at z = −1)
        const float z = inside ? depthInside(random) : depth(random), spread = inside ? -z : 1.2f;
        const glm::vec3 centre(unit(random) * spread, unit(random) * spread * 0.8f, z);
        const std::uint32_t first = std::uint32_t(scene.positions.size());
        for (int v = 0; v < 3; ++v)
            scene.positions.push_back(centre + glm::vec3(unit(random) * size, unit(random) * size,
                                                         unit(random) * (inside ? 0.5f : 4.0f)));
        scene.triangles.push_back({first, first + 1, first + 2});
        if (k % 7 == 0) scene.triangles.push_back({first, first + 1, first + 2});  // a duplicate
        if (k % 11 == 0) scene.triangles.push_back({first, first + 2, first + 1});  // the other winding
    }
    return scene;
}

// The soups' camera: 203×141 (cut by the tiles on both edges), fovy 70°, near 0.5, far 9.
inline CameraSpec kernelCamera(const char* convention, DepthFormat format, bool reversed, bool narrowRange)
{
    CameraSpec spec;
    spec.convention = Convention::preset(convention);
    spec.width = 203, spec.height = 141;
    spec.projection.fovyDeg = 70, spec.projection.near = 0.5, spec.projection.far = 9;
    spec.view = View::lookAt({0, 0, 0}, {0, 0, -1}, {0, 1, 0});
    spec.depth.format = format, spec.depth.reversed = reversed;
    if (narrowRange) spec.depth.rangeMin = 0.25, spec.depth.rangeMax = 0.75;
    return spec;
}

// Whether two arrays hold the same bits (memcmp: a signed zero or a NaN's payload would show).
template <class Vector>
bool sameBits(const Vector& a, const Vector& b)
{
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(a[0])) == 0;
}

// run() with the environment variable `variable` set to `value` (nullptr: unset), and then
// as it was before, also when run() throws, so that later tests see it unchanged.
template <class Run>
auto withEnvironment(const char* variable, const char* value, Run run)
{
    struct Restore {
        const char* variable;
        std::optional<std::string> before;
        ~Restore() { before ? setenv(variable, before->c_str(), 1) : unsetenv(variable); }
    } restore{variable, std::nullopt};
    if (const char* current = std::getenv(variable)) restore.before = current;
    if (value) setenv(variable, value, 1);
    else unsetenv(variable);
    return run();
}

// run() with ZCHECK_KERNELS set to `form` ("baseline", "avx2", "avx512"; nullptr: unset).
template <class Run>
auto inForm(const char* form, Run run)
{
    return withEnvironment("ZCHECK_KERNELS", form, run);
}

// The vector forms this processor runs, each to be compared with the baseline form; a WARN
// names each form it lacks (its bit-identity is then not tested on this machine).
inline std::vector<const char*> vectorFormsToTest()
{
    std::vector<const char*> forms;
    for (KernelForm form : {KernelForm::Avx2, KernelForm::Avx512}) {
        if (kernelFormSupported(form))
            forms.push_back(nameOf(form));
        else
            WARN("this processor cannot run the " << nameOf(form) << " form: its bit-identity to the baseline is skipped");
    }
    return forms;
}

// "baseline" and the vector forms this processor runs (vectorFormsToTest).
inline std::vector<const char*> everyFormToTest()
{
    std::vector<const char*> forms{"baseline"};
    for (const char* form : vectorFormsToTest()) forms.push_back(form);
    return forms;
}

}  // namespace zcheck::testing
