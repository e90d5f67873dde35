// zcheck._zcheck_files: datasets (dataset.h), adapted for zcheck/dataset.py. The rules — which
// frames a source holds, how each is read, how its camera is completed — are the library's.
#include "bindings.h"

#include "zcheck/camera_sources.h"
#include "zcheck/dataset.h"
#include "zcheck/dataset_report.h"
#include "zcheck/image_io.h"

#include <pybind11/functional.h>
#include <pybind11/stl.h>

namespace zcheck::python {

namespace {

DepthMapFile readMap(const std::string& path, const DepthMapReading& reading, int width, int height)
{
    return readDepthMap(path, reading, width, height);
}

// A dataset opened with the run's options: its runner (the scenes' verifiers built once).
struct PyDataset {
    std::shared_ptr<SceneVerifiers> verifiers = std::make_shared<SceneVerifiers>();
    std::unique_ptr<DatasetRunner> runner;
    const Dataset& dataset() const { return runner->dataset(); }
    const DatasetRunOptions& options() const { return runner->options(); }
};

DatasetRunOptions runOptions(const std::string& scene, std::optional<std::string> quantity, std::optional<double> scale,
                             std::optional<double> offset, const py::object& miss, std::optional<std::string> channel,
                             std::optional<double> near, std::optional<double> far, std::optional<std::string> convention,
                             bool diagnose, std::optional<std::string> shard, const py::dict& declared)
{
    DatasetRunOptions o;
    ReadingArguments arguments;
    arguments.quantum = declared["quantum"], arguments.relTolerance = declared["rel_tolerance"];
    arguments.absTolerance = declared["abs_tolerance"], arguments.allowHoles = declared["allow_holes"];
    arguments.noiseModel = declared["noise_model"];
    o.accuracy = readingOf(arguments).accuracy;
    o.scene = scene;
    o.quantity = quantity.value_or("");
    if (scale) DepthMapReading::requireScale(*scale, "scale");
    o.scale = scale, o.offset = offset;
    if (!miss.is_none()) o.miss = py::isinstance<py::str>(miss) ? miss.cast<std::string>() : formatNumber(miss.cast<double>());
    o.channel = channel.value_or("");
    o.near = near, o.far = far;
    o.convention = convention.value_or("");
    o.diagnose = diagnose;
    if (shard) o.parseShard(*shard);
    return o;
}

py::dict frameDict(const PyDataset& d, std::size_t index)
{
    const DatasetFrame& f = d.dataset().frames.at(index);
    py::dict out;
    out["index"] = f.index, out["name"] = f.name, out["depth"] = f.depth, out["error"] = f.error;
    try {
        const FramePlan plan = planFrame(f, d.options());
        py::dict reading;
        if (!plan.reading.channel.empty()) reading["channel"] = plan.reading.channel;
        if (plan.reading.scale > 0) reading["scale"] = plan.reading.scale;
        if (plan.reading.offset.value_or(0.0) != 0) reading["offset"] = *plan.reading.offset;
        if (plan.reading.miss.given()) reading["miss"] = plan.reading.miss.text();
        const MapAccuracy& declared = plan.reading.accuracy;
        if (declared.quantum > 0) reading["quantum"] = declared.quantum;
        if (declared.relative > 0) reading["rel_tolerance"] = declared.relative;
        if (declared.absolute > 0) reading["abs_tolerance"] = declared.absolute;
        if (declared.noise.any()) reading["noise_model"] = declared.noise.text();
        if (declared.allowHoles) reading["allow_holes"] = true;
        out["quantity"] = plan.quantityName, out["reading"] = reading, out["scene"] = plan.scene;
        out["notes"] = plan.notes;
    } catch (const Error& e) {
        if (f.error.empty()) out["error"] = std::string(e.what());
        out["quantity"] = py::none(), out["reading"] = py::dict(), out["scene"] = f.scene.value_or(d.options().scene);
    }
    if (f.camera) out["has_clip_planes"] = f.camera->hasClipPlanes, out["has_image_size"] = f.camera->hasImageSize;
    return out;
}

}  // namespace

void bindDatasets(py::module_& m)
{
    py::class_<PyDataset, std::shared_ptr<PyDataset>>(m, "_Dataset")
        .def(py::init([](const std::string& source, const std::string& scene, std::optional<std::string> quantity,
                         std::optional<std::string> depth, std::optional<std::string> cameraFormat, std::optional<double> scale,
                         std::optional<double> offset, const py::object& miss, std::optional<std::string> channel,
                         std::optional<double> near, std::optional<double> far, std::optional<std::string> convention,
                         bool diagnose, std::optional<std::string> shard, const py::dict& declared) {
                 auto d = std::make_shared<PyDataset>();
                 DatasetRunOptions options =
                     runOptions(scene, quantity, scale, offset, miss, channel, near, far, convention, diagnose, shard, declared);
                 DatasetSourceOptions sourceOptions;
                 sourceOptions.depthPattern = depth.value_or("");
                 if (cameraFormat) sourceOptions.cameraFormat = &cameraFormatNamed(*cameraFormat);
                 py::gil_scoped_release release;
                 Dataset dataset = openDataset(source, sourceOptions);
                 d->runner = std::make_unique<DatasetRunner>(std::move(dataset), std::move(options), readMap, d->verifiers);
                 return d;
             }),
             py::arg("source"), py::arg("scene"), py::arg("quantity"), py::arg("depth"), py::arg("camera_format"),
             py::arg("scale"), py::arg("offset"), py::arg("miss"), py::arg("channel"), py::arg("near"), py::arg("far"),
             py::arg("convention"), py::arg("diagnose"), py::arg("shard"), py::arg("declared"))
        .def("__len__", [](const PyDataset& d) { return d.dataset().frames.size(); })
        .def_property_readonly("source", [](const PyDataset& d) { return d.dataset().source; })
        .def_property_readonly("kind", [](const PyDataset& d) { return d.dataset().kind; })
        .def("frame", &frameDict, py::arg("index"))
        .def(
            "shard_frames",
            [](const PyDataset& d) { return d.runner->shardFrames(); })
        .def(
            "camera_and_map",
            [](const PyDataset& d, std::size_t index) {
                const DatasetFrame& frame = d.dataset().frames.at(index);
                CameraForMap made;
                {
                    py::gil_scoped_release release;
                    const FramePlan plan = planFrame(frame, d.options());
                    made = frameCameraAndMap(frame, plan, (*d.verifiers)(plan.scene).checker().scene(), d.options(), readMap);
                }
                return py::make_tuple(Camera(made.spec), image(made.map.value, made.map.width, made.map.height));
            },
            py::arg("index"))
        .def(
            "verify",
            [](const PyDataset& d, const std::vector<std::size_t>& frames, std::optional<int> threads) {
                std::vector<std::string> records;
                {
                    py::gil_scoped_release release;
                    const auto limit = threadLimit(threads);
                    d.runner->run(frames, [&](FrameResult&& result) { records.push_back(frameRecordJson(result)); });
                }
                return records;
            },
            py::arg("frames"), py::arg("threads"));
}

}  // namespace zcheck::python
