// zcheck.Scene: a triangle soup and its default camera (scene.h), from a name or from arrays.
#include "bindings.h"

#include "zcheck/mesh_loader.h"
#include "zcheck/scene.h"

#include <cmath>
#include <cstdint>

namespace zcheck::python {

namespace {

// An (N, 3) array of N three-element vectors (positions, a triangle's vertex indices).
template <class T, class Vector>
py::array_t<T> rowsOf(const std::vector<Vector>& vectors)
{
    py::array_t<T> out({py::ssize_t(vectors.size()), py::ssize_t(3)});
    auto v = out.template mutable_unchecked<2>();
    for (std::size_t i = 0; i < vectors.size(); ++i)
        for (int k = 0; k < 3; ++k) v(py::ssize_t(i), k) = vectors[i][k];
    return out;
}

Scene sceneFromArrays(py::object vertices, py::object triangles, const std::string& name)
{
    const std::string where = "Scene.from_arrays: ";
    const py::array v = numericArray(vertices, where + "vertices");
    if (v.ndim() != 2 || v.shape(1) != 3 || v.shape(0) < 1)
        fail(where + "vertices must have shape (N, 3) with N >= 1, got " + shapeText(v));
    const py::array t = numericArray(triangles, where + "triangles");
    if (t.dtype().kind() == 'f')
        fail(where + "triangles must be an integer array of vertex indices, got dtype " + dtypeText(t));
    if (t.ndim() != 2 || t.shape(1) != 3 || t.shape(0) < 1)
        fail(where + "triangles must have shape (M, 3) with M >= 1, got " + shapeText(t));
    if (name.empty()) fail(where + "name is empty");

    Scene scene;
    scene.name = name;
    const DoubleArray vd = asDoubles(v);
    const auto pv = vd.unchecked<2>();
    scene.positions.resize(std::size_t(vd.shape(0)));
    for (py::ssize_t i = 0; i < vd.shape(0); ++i) {
        for (int k = 0; k < 3; ++k) {
            const double x = pv(i, k);
            const float f = float(x);
            if (!std::isfinite(x) || !std::isfinite(f))
                fail(where + "vertices[" + std::to_string(i) + ", " + std::to_string(k) + "] = " + formatNumber(x) +
                     (std::isfinite(x) ? " does not fit in binary32" : " is not finite"));
        }
        scene.positions[std::size_t(i)] = scene.rounding.store({pv(i, 0), pv(i, 1), pv(i, 2)});
    }
    const std::size_t n = scene.positions.size();
    const bool isSigned = t.dtype().kind() == 'i';
    // Unsigned indices are read as uint64, signed as int64: no value changes on the way.
    scene.triangles.resize(std::size_t(t.shape(0)));
    auto setIndex = [&](py::ssize_t j, int k, long double index) {
        if (index < 0 || index >= static_cast<long double>(n))
            fail(where + "triangles[" + std::to_string(j) + ", " + std::to_string(k) + "] = " +
                 std::to_string(static_cast<long long>(index)) + " is not a vertex index (0.." + std::to_string(n - 1) +
                 " for " + std::to_string(n) + " vertices)");
        scene.triangles[std::size_t(j)][k] = std::uint32_t(index);
    };
    if (isSigned) {
        const auto ti = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(t);
        const auto pt = ti.unchecked<2>();
        for (py::ssize_t j = 0; j < ti.shape(0); ++j)
            for (int k = 0; k < 3; ++k) setIndex(j, k, static_cast<long double>(pt(j, k)));
    } else {
        const auto tu = py::array_t<std::uint64_t, py::array::c_style | py::array::forcecast>::ensure(t);
        const auto pt = tu.unchecked<2>();
        for (py::ssize_t j = 0; j < tu.shape(0); ++j)
            for (int k = 0; k < 3; ++k) setIndex(j, k, static_cast<long double>(pt(j, k)));
    }
    // The mesh loader's rule (scene.h): something with area to draw, and a camera framing it.
    scene = frameScene(std::move(scene), "Scene.from_arrays: the mesh");
    return scene;
}

}  // namespace

void bindScene(py::module_& m)
{
    py::class_<Scene>(m, "Scene", R"doc(A triangle soup in world space (binary32 positions, uint32 indices) and the
camera it is best looked at with (Scene.default_camera).

Build one with Scene.from_file(...) or Scene.from_arrays(...).)doc")
        .def_static(
            "from_file",
            [](const std::string& nameOrPath) {
                py::gil_scoped_release release;
                return loadScene(nameOrPath);
            },
            py::arg("path"),
            R"doc(Load a scene by name, exactly as `zcheck check --scene` does.

path: "builtin:default", "builtin:terrain?n=64", "builtin:near-crossing", or a mesh file (OBJ,
PLY including triangle strips, STL, glTF/glb). A mesh's default camera frames its bounding sphere.
Raises zcheck.Error naming the file or scene for anything missing, unreadable or malformed.)doc")
        .def_static("from_arrays", &sceneFromArrays, py::arg("vertices"), py::arg("triangles"),
                    py::arg("name") = "arrays",
                    R"doc(A scene from numpy arrays.

vertices:  (N, 3) numbers, world coordinates; stored as binary32 (what GPUs and Embree use), so
           each must be finite and fit in binary32 and within +-1e15.
triangles: (M, 3) integers, indices into vertices (any integer dtype); triangle k is primitive k.
name:      the scene's name in reports.
Degenerate (zero-area) triangles are kept, but at least one must have area. The default camera
frames the bounding sphere, by the same rule as a loaded mesh file.
Raises zcheck.Error naming the argument, the entry and the rule.)doc")
        .def_property_readonly("name", [](const Scene& s) { return s.name; }, "The scene's name as addressed.")
        .def_property_readonly("vertex_count", [](const Scene& s) { return s.positions.size(); })
        .def_property_readonly("triangle_count", &Scene::triangleCount)
        .def_property_readonly(
            "vertices",
            [](const Scene& s) { return rowsOf<float>(s.positions); },
            "(N, 3) float32 copy of the positions, in the scene's frame: world = origin + vertex.")
        .def_property_readonly(
            "origin", [](const Scene& s) { return arrayFromVec3(s.origin); },
            "The world point the vertices are held about: (0, 0, 0), but for a mesh whose coordinates binary32\n"
            "would have moved materially (far from the origin against its size: UTM, ECEF), held about the\n"
            "centre of its box as large-world renderers hold it. Cameras are always given in the world.")
        .def_property_readonly(
            "triangles",
            [](const Scene& s) { return rowsOf<std::uint32_t>(s.triangles); },
            "(M, 3) uint32 copy of the vertex indices; row k is primitive id k.")
        .def_property_readonly(
            "bounds",
            [](const Scene& s) {
                return py::make_tuple(arrayFromVec3(s.worldFromScene(s.boundsMin())), arrayFromVec3(s.worldFromScene(s.boundsMax())));
            },
            "(min, max) corners of the axis-aligned bounding box, world coordinates.")
        .def_property_readonly(
            "default_camera", [](const Scene& s) { return makeCamera(s.defaultCamera, "Scene.default_camera"); },
            "The camera `zcheck check` uses when no camera file is given.")
        .def(py::pickle(&sceneState, &sceneFromState))
        .def("__repr__", [](const Scene& s) {
            return "<zcheck.Scene '" + s.name + "': " + std::to_string(s.positions.size()) + " vertices, " +
                   std::to_string(s.triangles.size()) + " triangles>";
        });
}

}  // namespace zcheck::python
