// Pickling of Camera, Scene and Report, so that multiprocessing, concurrent.futures and any
// engine that pickles can send them between processes. Each state is plain Python values:
//   Camera  its camera file's JSON (exact: every number round-trips), its notes and the pose
//           rule's departure
//   Scene   its source — a built-in scene's name or a mesh file's path, loaded again — or, for
//           Scene.from_arrays and a file that is gone, its vertices and triangles
//   Report  every number of the report, the JSON and summary texts, the per-pixel arrays
#include "bindings.h"

#include "zcheck/camera_file.h"
#include "zcheck/mesh_loader.h"

#include <pybind11/stl.h>

#include <sys/stat.h>

namespace zcheck::python {

namespace {

template <class T>
py::bytes bytesOf(const T* data, std::size_t count)
{
    return py::bytes(reinterpret_cast<const char*>(data), count * sizeof(T));
}

template <class Vector>
void assignBytes(Vector& out, const py::bytes& bytes)
{
    const std::string raw = bytes;
    using T = typename Vector::value_type;
    if (raw.size() % sizeof(T) != 0) fail("a pickled Report's pixel array is damaged");
    out.resize(raw.size() / sizeof(T));
    if (!raw.empty()) std::memcpy(out.data(), raw.data(), raw.size());
}

py::tuple findingState(const PixelFinding& f)
{
    return py::make_tuple(f.col, f.row, int(f.pixelClass), f.rayWindowDepth, f.rasterWindowDepth, f.errorQuanta,
                          f.toleranceQuanta, f.rayPrimitive, f.rasterPrimitive);
}

PixelFinding findingFrom(const py::tuple& t)
{
    PixelFinding f;
    f.col = t[0].cast<int>(), f.row = t[1].cast<int>(), f.pixelClass = PixelClass(t[2].cast<int>());
    f.rayWindowDepth = t[3].cast<double>(), f.rasterWindowDepth = t[4].cast<double>();
    f.errorQuanta = t[5].cast<double>(), f.toleranceQuanta = t[6].cast<double>();
    f.rayPrimitive = t[7].cast<std::uint32_t>(), f.rasterPrimitive = t[8].cast<std::uint32_t>();
    return f;
}

// The comparison report's fields by name: one list for both directions.
#define ZCHECK_COMPARISON_FIELDS(F)                                                                                    \
    F(width) F(height) F(bothHit) F(bothMiss) F(rayOnly) F(rasterOnly) F(agree) F(edgeSurface) F(depthErrors)          \
    F(coverageExplained) F(lostAtClearValue) F(atClipPlane) F(coverageUnexplained) F(maxErrorQuanta) F(p99ErrorQuanta) \
    F(maxErrorOverTolerance) F(maxRelativeEyeZError) F(p99RelativeEyeZError) F(unexplainedMinCol)                      \
    F(unexplainedMinRow) F(unexplainedMaxCol) F(unexplainedMaxRow) F(biasSamples) F(meanSignedErrorQuanta) F(depthBias)

py::dict comparisonState(const ComparisonReport& c)
{
    py::dict d;
#define ZCHECK_SAVE(field) d[#field] = c.field;
    ZCHECK_COMPARISON_FIELDS(ZCHECK_SAVE)
#undef ZCHECK_SAVE
    d["worst"] = findingState(c.worst);
    py::list samples;
    for (const PixelFinding& f : c.unexplainedSamples) samples.append(findingState(f));
    d["unexplainedSamples"] = samples;
    return d;
}

ComparisonReport comparisonFrom(const py::dict& d)
{
    ComparisonReport c;
#define ZCHECK_LOAD(field) c.field = d[#field].cast<decltype(c.field)>();
    ZCHECK_COMPARISON_FIELDS(ZCHECK_LOAD)
#undef ZCHECK_LOAD
    c.worst = findingFrom(d["worst"].cast<py::tuple>());
    for (const py::handle f : d["unexplainedSamples"]) c.unexplainedSamples.push_back(findingFrom(f.cast<py::tuple>()));
    return c;
}

py::tuple hypothesisState(const Hypothesis& h)
{
    py::list fitted;
    for (const FittedValue& v : h.fitted) fitted.append(py::make_tuple(v.name, v.value, v.declared));
    return py::make_tuple(h.name, h.variant, h.explanation, h.consistent, h.unexplained, h.estimated, fitted,
                          h.unexplainedAtEdges, h.blendsAtEdges, h.compared);
}

Hypothesis hypothesisFrom(const py::tuple& t)
{
    Hypothesis h;
    h.name = t[0].cast<std::string>(), h.variant = t[1].cast<std::string>(), h.explanation = t[2].cast<std::string>();
    h.consistent = t[3].cast<bool>(), h.unexplained = t[4].cast<std::int64_t>(), h.estimated = t[5].cast<bool>();
    for (const py::handle v : t[6]) {
        const py::tuple f = v.cast<py::tuple>();
        h.fitted.push_back({f[0].cast<std::string>(), f[1].cast<double>(), f[2].cast<double>()});
    }
    h.unexplainedAtEdges = t[7].cast<std::int64_t>(), h.blendsAtEdges = t[8].cast<std::int64_t>();
    h.compared = t[9].cast<std::int64_t>();
    return h;
}

bool isFile(const std::string& path)
{
    struct stat status {};
    return ::stat(path.c_str(), &status) == 0 && S_ISREG(status.st_mode);
}

}  // namespace

py::tuple cameraState(const Camera& camera)
{
    const CameraSpec& spec = camera.spec();
    return py::make_tuple(cameraJsonText(spec), spec.notes, spec.view.rotationDeparture);
}

Camera cameraFromState(const py::tuple& state)
{
    if (state.size() != 3) fail("a pickled Camera is damaged");
    CameraSpec spec = cameraSpecFromJsonText(state[0].cast<std::string>(), "pickled camera");
    spec.notes = state[1].cast<std::vector<std::string>>();
    spec.view.rotationDeparture = state[2].cast<double>();
    return Camera(spec);
}

py::tuple sceneState(const Scene& scene)
{
    if (isBuiltinSceneName(scene.name) || isFile(scene.name)) return py::make_tuple("source", scene.name);
    const PositionRounding& r = scene.rounding;  // what the arrays' binary64 values lost, for the reports
    return py::make_tuple("arrays", scene.name, bytesOf(scene.positions.data(), scene.positions.size()),
                          bytesOf(scene.triangles.data(), scene.triangles.size()),
                          py::make_tuple(r.largestMove, r.movedVertex.x, r.movedVertex.y, r.movedVertex.z),
                          py::make_tuple(scene.origin.x, scene.origin.y, scene.origin.z), r.size);
}

Scene sceneFromState(const py::tuple& state)
{
    const std::string kind = state[0].cast<std::string>();
    if (kind == "source") return loadScene(state[1].cast<std::string>());
    Scene scene;
    scene.name = state[1].cast<std::string>();
    assignBytes(scene.positions, state[2].cast<py::bytes>());
    assignBytes(scene.triangles, state[3].cast<py::bytes>());
    if (state.size() > 4) {
        const auto r = state[4].cast<std::tuple<double, double, double, double>>();
        scene.rounding.largestMove = std::get<0>(r);
        scene.rounding.movedVertex = {std::get<1>(r), std::get<2>(r), std::get<3>(r)};
    }
    if (state.size() > 5) {  // the local origin its positions are held about (Scene::origin)
        const auto o = state[5].cast<std::tuple<double, double, double>>();
        scene.origin = {std::get<0>(o), std::get<1>(o), std::get<2>(o)};
        for (int k = 0; k < 3; ++k)
            if (!(std::abs(scene.origin[k]) <= 1e15))
                throw Error("a pickled Scene: its origin (" + formatNumber(scene.origin.x) + ", " + formatNumber(scene.origin.y) +
                            ", " + formatNumber(scene.origin.z) + ") is not a point within 1e15 of the world's");
    }
    scene = frameScene(std::move(scene), "a pickled Scene");
    if (state.size() > 6) scene.rounding.size = state[6].cast<double>();  // the file's mesh's, as the warning gave it
    return scene;
}

py::tuple reportState(const PyReport& r)
{
    const CheckReport& c = r.report;
    py::list diagnosis;
    if (r.diagnosis)
        for (const Hypothesis& h : *r.diagnosis) diagnosis.append(hypothesisState(h));
    const py::tuple report = py::make_tuple(
        c.scene, c.triangles, cameraState(Camera(c.camera)), c.tolerance.subpixelBits, int(c.tolerance.slopeCredit),
        comparisonState(c.comparison),
        py::make_tuple(c.timings.bvhBuildMs, c.timings.traceMs, c.timings.rasterMs, c.timings.compareMs, c.timings.tileByTile),
        c.warnings);
    return py::make_tuple(report, r.verify, r.json, r.summary, r.pixelsKept, bytesOf(r.pixelClass.data(), r.pixelClass.size()),
                          bytesOf(r.errorOverTolerance.data(), r.errorOverTolerance.size()),
                          bytesOf(r.rayWindowDepth.data(), r.rayWindowDepth.size()),
                          bytesOf(r.comparedWindowDepth.data(), r.comparedWindowDepth.size()),
                          r.diagnosis ? py::object(diagnosis) : py::object(py::none()));
}

PyReport reportFromState(const py::tuple& state)
{
    if (state.size() != 10) fail("a pickled Report is damaged");
    PyReport r;
    const py::tuple report = state[0].cast<py::tuple>();
    CheckReport& c = r.report;
    c.scene = report[0].cast<std::string>();
    c.triangles = report[1].cast<std::size_t>();
    c.camera = cameraFromState(report[2].cast<py::tuple>()).spec();
    c.tolerance.subpixelBits = report[3].cast<int>();
    c.tolerance.slopeCredit = SlopeCredit(report[4].cast<int>());
    c.comparison = comparisonFrom(report[5].cast<py::dict>());
    const py::tuple timings = report[6].cast<py::tuple>();
    c.timings = {timings[0].cast<double>(), timings[1].cast<double>(), timings[2].cast<double>(), timings[3].cast<double>(),
                 timings[4].cast<bool>()};
    c.warnings = report[7].cast<std::vector<std::string>>();
    r.verify = state[1].cast<bool>();
    r.json = state[2].cast<std::string>();
    r.summary = state[3].cast<std::string>();
    r.pixelsKept = state[4].cast<bool>();
    assignBytes(r.pixelClass, state[5].cast<py::bytes>());
    assignBytes(r.errorOverTolerance, state[6].cast<py::bytes>());
    assignBytes(r.rayWindowDepth, state[7].cast<py::bytes>());
    assignBytes(r.comparedWindowDepth, state[8].cast<py::bytes>());
    if (!state[9].is_none()) {
        std::vector<Hypothesis> diagnosis;
        for (const py::handle h : state[9]) diagnosis.push_back(hypothesisFrom(h.cast<py::tuple>()));
        r.diagnosis = std::move(diagnosis);
    }
    return r;
}

}  // namespace zcheck::python
