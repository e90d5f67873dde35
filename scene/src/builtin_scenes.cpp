// Built-in scenes: procedural geometry with known shape, each with the camera it is meant
// to be seen with. Every scene is deliberately asymmetric (left/right and top/bottom), so a
// flipped or shifted image can never match the true one.
#include "zcheck/detail/streaming_stores.h"
#include "zcheck/error.h"
#include "zcheck/large_buffer.h"
#include "zcheck/scene.h"

#include <glm/gtc/constants.hpp>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <map>

namespace zcheck {

namespace {

struct Soup {
    std::vector<glm::vec3> positions;
    std::vector<glm::uvec3> triangles;

    std::uint32_t vertex(const glm::dvec3& p)
    {
        positions.emplace_back(p);
        return static_cast<std::uint32_t>(positions.size() - 1);
    }
    // A quad a-b-c-d as two triangles.
    void quad(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& d)
    {
        const std::uint32_t ia = vertex(a), ib = vertex(b), ic = vertex(c), id = vertex(d);
        triangles.push_back({ia, ib, ic});
        triangles.push_back({ia, ic, id});
    }
    // A closed box: centre, half extents, rotation about the y axis then about the x axis.
    void box(const glm::dvec3& centre, const glm::dvec3& half, double yawDeg = 0.0, double pitchDeg = 0.0)
    {
        const double cy = std::cos(glm::radians(yawDeg)), sy = std::sin(glm::radians(yawDeg));
        const double cp = std::cos(glm::radians(pitchDeg)), sp = std::sin(glm::radians(pitchDeg));
        auto corner = [&](int i) {
            glm::dvec3 p((i & 1 ? 1 : -1) * half.x, (i & 2 ? 1 : -1) * half.y, (i & 4 ? 1 : -1) * half.z);
            p = {p.x, cp * p.y - sp * p.z, sp * p.y + cp * p.z};    // pitch about x
            p = {cy * p.x + sy * p.z, p.y, -sy * p.x + cy * p.z};  // yaw about y
            return centre + p;
        };
        const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
        for (const auto& f : faces) quad(corner(f[0]), corner(f[1]), corner(f[2]), corner(f[3]));
    }
    // A UV sphere; shared vertices so the surface is watertight.
    void sphere(const glm::dvec3& centre, double radius, int slices = 32, int stacks = 20)
    {
        const auto first = static_cast<std::uint32_t>(positions.size());
        for (int i = 0; i <= stacks; ++i) {
            const double theta = glm::pi<double>() * i / stacks;
            for (int j = 0; j < slices; ++j) {
                const double phi = 2 * glm::pi<double>() * j / slices;
                vertex(centre + radius * glm::dvec3(std::sin(theta) * std::cos(phi), std::cos(theta),
                                                    std::sin(theta) * std::sin(phi)));
            }
        }
        auto at = [&](int i, int j) { return first + static_cast<std::uint32_t>(i * slices + (j % slices)); };
        for (int i = 0; i < stacks; ++i)
            for (int j = 0; j < slices; ++j) {
                if (i > 0) triangles.push_back({at(i, j), at(i, j + 1), at(i + 1, j)});
                if (i < stacks - 1) triangles.push_back({at(i, j + 1), at(i + 1, j + 1), at(i + 1, j)});
            }
    }
    // A grid of (n−1)² quads over [x0,x1] × [z0,z1] with height y = height(x, z).
    template <class Height>
    void heightfield(int n, double x0, double x1, double z0, double z1, Height height)
    {
        const auto first = static_cast<std::uint32_t>(positions.size());
        const std::size_t firstTriangle = triangles.size();
        reserveLarge(positions, positions.size() + std::size_t(n) * n);
        reserveLarge(triangles, triangles.size() + 2 * std::size_t(n - 1) * (n - 1));
        positions.resize(positions.size() + std::size_t(n) * n);
        triangles.resize(triangles.size() + 2 * std::size_t(n - 1) * (n - 1));
        // Row by row in parallel (ten million triangles are a large part of a check's time):
        // each vertex and triangle where the serial loops put them, with the same values.
        tbb::parallel_for(0, n, [&](int i) {
            for (int j = 0; j < n; ++j) {
                const double x = x0 + (x1 - x0) * j / (n - 1), z = z0 + (z1 - z0) * i / (n - 1);
                positions[first + std::size_t(i) * n + j] = glm::vec3(glm::dvec3(x, height(x, z), z));
            }
        });
        auto at = [&](int i, int j) { return first + static_cast<std::uint32_t>(i * n + j); };
        tbb::parallel_for(0, n - 1, [&](int i) {
            glm::uvec3* row = triangles.data() + firstTriangle + 2 * std::size_t(i) * (n - 1);
            for (int j = 0; j + 1 < n; ++j) {
                row[2 * j] = {at(i, j), at(i + 1, j), at(i + 1, j + 1)};
                row[2 * j + 1] = {at(i, j), at(i + 1, j + 1), at(i, j + 1)};
            }
        });
    }
};

Scene sceneFrom(const std::string& name, Soup&& soup, const CameraSpec& camera)
{
    Scene scene;
    scene.name = name;
    scene.positions = std::move(soup.positions);
    scene.triangles = std::move(soup.triangles);
    scene.defaultCamera = camera;
    return scene;
}

Scene defaultScene()
{
    Soup s;
    s.heightfield(9, -12.0, 12.0, -30.0, 6.0, [](double, double) { return 0.0; });  // ground, y = 0
    s.box({-2.2, 0.6, -1.0}, {0.6, 0.6, 0.6}, 25.0);                               // near left
    s.box({1.8, 1.2, -6.0}, {0.8, 1.2, 0.5}, -15.0);                               // tall, middle right
    s.box({-4.5, 0.5, -14.0}, {1.5, 0.5, 1.0}, 40.0);                              // far left, low
    s.sphere({0.4, 0.7, 0.6}, 0.7);                                                 // near, centre
    s.sphere({-0.8, 1.5, -9.0}, 1.5);                                               // far, large
    s.sphere({5.0, 3.2, -20.0}, 1.0, 24, 16);                                       // very far, high right
    s.box({3.2, 1.3, -2.5}, {0.02, 1.1, 0.9}, 55.0, 20.0);                          // thin slanted panel
    // Two nearly coplanar, partly overlapping quads 2 mm apart: resolved in float32 and
    // unorm24, z-fighting in unorm16 at this distance, so the tolerance model is exercised.
    s.quad({-1.6, 2.2, -4.0}, {0.2, 2.2, -4.0}, {0.2, 3.4, -4.0}, {-1.6, 3.4, -4.0});
    s.quad({-1.0, 2.5, -4.002}, {0.8, 2.5, -4.002}, {0.8, 3.9, -4.002}, {-1.0, 3.9, -4.002});

    CameraSpec camera;
    camera.projection = Projection::perspective(55.0, 0.1, 100.0);
    camera.view = View::lookAt({1.2, 2.4, 5.5}, {-0.3, 0.9, -4.0}, {0.0, 1.0, 0.0});
    return sceneFrom("builtin:default", std::move(s), camera);
}

// `size`: the side of the square; the whole shape (heights and the camera too) scales with it.
Scene terrainScene(const std::string& name, int n, double size)
{
    Soup s;
    const double k = size / 100.0;  // the shape is defined on a side of 100
    // Smooth, asymmetric hills with fine detail: sum of incommensurate sines.
    s.heightfield(n, -50.0 * k, 50.0 * k, -50.0 * k, 50.0 * k, [k](double xs, double zs) {
        const double x = xs / k, z = zs / k;
        return k * (3.0 * std::sin(0.11 * x + 0.3) * std::cos(0.07 * z - 0.2) + 1.2 * std::sin(0.31 * x + 0.23 * z) +
                    0.35 * std::sin(1.3 * x - 0.9 * z + 1.0) + 0.04 * x);
    });
    CameraSpec camera;
    camera.width = 640;
    camera.height = 480;
    camera.projection = Projection::perspective(50.0, 0.5 * k, 200.0 * k);
    camera.view = View::lookAt(glm::dvec3(-35.0, 14.0, 42.0) * k, glm::dvec3(8.0, -2.0, -10.0) * k, {0.0, 1.0, 0.0});
    return sceneFrom(name, std::move(s), camera);
}

Scene nearCrossingScene()
{
    Soup s;
    // The camera stands at the origin looking down −z with near = 0.5.
    s.heightfield(5, -6.0, 6.0, -12.0, 8.0, [](double, double) { return -1.0; });   // floor, runs behind the eye
    s.quad({2.0, -1.0, 6.0}, {2.0, -1.0, -10.0}, {2.0, 2.0, -10.0}, {2.0, 2.0, 6.0}); // right wall, behind too
    s.box({-0.3, 0.1, -0.5}, {0.25, 0.2, 0.3}, 30.0);      // straddles the near plane at the image centre
    s.box({-1.2, -0.6, -0.2}, {0.4, 0.3, 0.6}, -20.0);     // crosses the near plane and the eye plane
    // One big triangle with a vertex behind the camera, one beside it and one far ahead.
    s.positions.emplace_back(-3.0f, 1.5f, 3.0f);
    s.positions.emplace_back(1.0f, 0.8f, -2.0f);
    s.positions.emplace_back(-4.0f, -0.5f, -8.0f);
    const auto last = static_cast<std::uint32_t>(s.positions.size());
    s.triangles.push_back({last - 3, last - 2, last - 1});
    s.sphere({1.0, 0.0, -3.0}, 0.6);

    CameraSpec camera;
    camera.projection = Projection::perspective(70.0, 0.5, 50.0);
    camera.view = View::lookAt({0.0, 0.0, 0.0}, {0.0, 0.0, -1.0}, {0.0, 1.0, 0.0});
    return sceneFrom("builtin:near-crossing", std::move(s), camera);
}

// "terrain?n=708" → base "terrain", params {n: 708}.
std::map<std::string, std::string> parseParameters(const std::string& query, const std::string& fullName)
{
    std::map<std::string, std::string> params;
    std::size_t start = 0;
    while (start < query.size()) {
        const std::size_t end = std::min(query.find('&', start), query.size());
        const std::string item = query.substr(start, end - start);
        const std::size_t eq = item.find('=');
        if (eq == std::string::npos || eq == 0)
            throw Error("scene '" + fullName + "': parameter '" + item + "' is not of the form key=value");
        params[item.substr(0, eq)] = item.substr(eq + 1);
        start = end + 1;
    }
    return params;
}

}  // namespace

bool isBuiltinSceneName(const std::string& name) { return name.rfind("builtin:", 0) == 0; }

const std::vector<std::string>& builtinSceneNames()
{
    static const std::vector<std::string> names = {"default", "terrain", "near-crossing"};
    return names;
}

Scene builtinScene(const std::string& fullName)
{
    const std::string rest = isBuiltinSceneName(fullName) ? fullName.substr(8) : fullName;
    const std::size_t question = rest.find('?');
    const std::string base = rest.substr(0, question);
    auto params = parseParameters(question == std::string::npos ? "" : rest.substr(question + 1), fullName);
    auto rejectUnknown = [&](const std::vector<std::string>& known) {
        for (const auto& [key, value] : params)
            if (std::find(known.begin(), known.end(), key) == known.end())
                throw Error("scene '" + fullName + "': unknown parameter '" + key + "'");
    };
    if (base == "default") {
        rejectUnknown({});
        return defaultScene();
    }
    if (base == "near-crossing") {
        rejectUnknown({});
        return nearCrossingScene();
    }
    if (base == "terrain") {
        rejectUnknown({"n", "size"});
        int n = 256;
        double size = 100.0;
        if (params.count("n")) {
            const std::string& text = params["n"];
            char* end = nullptr;
            const long value = std::strtol(text.c_str(), &end, 10);
            if (text.empty() || *end != '\0' || value < 2 || value > 4096)
                throw Error("scene '" + fullName + "': 'n' must be an integer in 2..4096, got '" + text + "'");
            n = static_cast<int>(value);
        }
        if (params.count("size")) {
            const std::string& text = params["size"];
            char* end = nullptr;
            const double value = std::strtod(text.c_str(), &end);
            if (text.empty() || *end != '\0' || !(value >= 1e-3 && value <= 1e6))
                throw Error("scene '" + fullName + "': 'size' must be a number in 0.001..1e6, got '" + text + "'");
            size = value;
        }
        return terrainScene("builtin:" + rest, n, size);
    }
    std::string known;
    for (const auto& name : builtinSceneNames()) known += (known.empty() ? "builtin:" : ", builtin:") + name;
    throw Error("unknown built-in scene '" + fullName + "' (expected one of " + known + ")");
}

}  // namespace zcheck
