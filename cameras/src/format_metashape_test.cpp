// Metashape's cameras.xml (format_metashape.cpp) against poses and projections computed
// independently with numpy from the same XML (tests/data/metashape/expected.py, whose notes
// cite the sources for each convention): the 1.x layout (chunk transform) and the 2.x layout
// (component transform) of one scene, the refusals, and a file of 4,000 cameras.
#include "zcheck/camera_formats.h"
#include "zcheck/camera_import.h"
#include "zcheck/dataset_source.h"
#include "zcheck/detail/json.h"
#include "zcheck/error.h"
#include "zcheck/input_file.h"
#include "zcheck/pose.h"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <unistd.h>

using namespace zcheck;
namespace fs = std::filesystem;

namespace {

const fs::path kData = fs::path(ZCHECK_TESTS_DIR) / "data" / "metashape";

fs::path scratch(const std::string& name)
{
    const fs::path dir = fs::temp_directory_path() / ("zcheck_metashape_" + std::to_string(::getpid())) / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

std::string writeText(const fs::path& path, const std::string& text)
{
    std::ofstream(path, std::ios::binary) << text;
    return path.string();
}

// The pixel (top-left pixel's centre at 0.5, 0.5) and eye-z of a world point.
std::pair<glm::dvec2, double> projected(const CameraSpec& spec, const glm::dvec3& world)
{
    const Camera camera(spec);
    const glm::dvec4 clip = camera.clipFromWorld * glm::dvec4(world, 1.0);
    const glm::dvec4 window = camera.windowFromNdc * (clip / clip.w);
    const glm::dvec4 eye = camera.eyeFromWorld * glm::dvec4(world, 1.0);
    return {{window.x, camera.imageYFromWindowY(window.y)}, eye.z};
}

// A minimal frame-camera file: one sensor, the chunk transform given, cameras as given.
std::string documentWith(const std::string& cameras, const std::string& chunkExtra = "", const std::string& calibration = "")
{
    return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<document version=\"1.5.0\">\n  <chunk label=\"c\">\n"
           "    <sensors next_id=\"1\">\n      <sensor id=\"0\" label=\"s\" type=\"frame\">\n"
           "        <resolution width=\"64\" height=\"48\"/>\n        <calibration type=\"frame\" class=\"adjusted\">\n"
           "          <resolution width=\"64\" height=\"48\"/>\n          <f>50</f>\n" +
           calibration + "        </calibration>\n      </sensor>\n    </sensors>\n    <cameras>\n" + cameras +
           "    </cameras>\n" + chunkExtra + "  </chunk>\n</document>\n";
}

std::string cameraElement(int id, const std::string& extra = "", const std::string& transform = "1 0 0 0 0 1 0 0 0 0 1 -3 0 0 0 1")
{
    return "      <camera id=\"" + std::to_string(id) + "\" sensor_id=\"0\" label=\"IMG_" + std::to_string(id) + ".JPG\"" +
           extra + ">\n        <transform>" + transform + "</transform>\n      </camera>\n";
}

}  // namespace

TEST_CASE("Metashape cameras.xml: poses and intrinsics as numpy computes them, in the 1.x and 2.x layouts")
{
    const nlohmann::json expected =
        parseJsonStrictly(readInputFile((kData / "expected.json").string(), kManifestInput), "expected.json");
    for (const char* file : {"frames.xml", "frames_v2.xml"}) {
        INFO(file);
        const std::string path = (kData / file).string();
        REQUIRE(detectCameraFormat(path).name == "metashape");
        const CameraSet set = readCameraSet(path);
        REQUIRE(set.format == "metashape");
        std::size_t usable = 0, listed = 0;
        for (const auto& [label, want] : expected["cameras"].items()) {
            INFO(label);
            const std::string reason = want["reason"].get<std::string>();
            auto found = std::find_if(set.cameras.begin(), set.cameras.end(),
                                      [&, name = label](const ImportedCamera& c) { return c.name == name; });
            if (reason == "disabled") {  // skipped, as Metashape's own exporters skip it
                REQUIRE(found == set.cameras.end());
                continue;
            }
            REQUIRE(found != set.cameras.end());
            ++listed;
            if (reason == "not_aligned") REQUIRE_THAT(found->refusal, Catch::Contains("is not aligned"));
            if (reason == "sensor_has_distortion")
                REQUIRE_THAT(found->refusal, Catch::Contains("has lens distortion") && Catch::Contains("k1 = "));
            if (!want["usable"].get<bool>()) {
                REQUIRE_FALSE(found->refusal.empty());
                REQUIRE_THROWS_WITH(set.find(label), Catch::Contains(found->refusal));
                continue;
            }
            ++usable;
            REQUIRE(found->refusal.empty());
            const CameraSpec& spec = found->spec;
            REQUIRE(spec.width == want["width"].get<int>());
            REQUIRE(spec.height == want["height"].get<int>());
            REQUIRE(spec.convention.name == "opencv");
            for (const nlohmann::json& probe : want["projections"]) {
                const glm::dvec3 world{probe["world"][0].get<double>(), probe["world"][1].get<double>(),
                                       probe["world"][2].get<double>()};
                const auto [pixel, depth] = projected(spec, world);
                REQUIRE(pixel.x == Approx(probe["pixel"][0].get<double>()).margin(1e-9));
                REQUIRE(pixel.y == Approx(probe["pixel"][1].get<double>()).margin(1e-9));
                REQUIRE(depth == Approx(probe["depth"].get<double>()).margin(1e-12));
            }
            const Camera camera(spec);
            for (int row = 0; row < 4; ++row)
                for (int col = 0; col < 4; ++col)
                    REQUIRE(camera.eyeFromWorld[col][row] == Approx(want["camera_from_world"][row][col].get<double>()).margin(1e-12));
            // By image name, by stem, by Metashape's camera id.
            REQUIRE(set.find(label) == std::size_t(found - set.cameras.begin()));
            REQUIRE(set.find(label.substr(0, label.find('.'))) == std::size_t(found - set.cameras.begin()));
            REQUIRE(set.find("id" + std::to_string(want["camera_id"].get<int>())) == std::size_t(found - set.cameras.begin()));
        }
        REQUIRE(usable == expected["usable_count"].get<std::size_t>());
        REQUIRE(listed == set.cameras.size());
    }
}

TEST_CASE("Metashape cameras.xml is a dataset source whose depth maps --depth names")
{
    DatasetSourceOptions options;
    options.depthPattern = "depth/{stem}.exr";
    const Dataset dataset = openDataset((kData / "frames.xml").string(), options);
    REQUIRE(dataset.kind == "metashape");
    std::size_t ready = 0;
    for (const DatasetFrame& frame : dataset.frames) {
        REQUIRE(frame.depth == "depth/" + frame.name.substr(0, frame.name.find('.')) + ".exr");
        ready += frame.error.empty();
    }
    REQUIRE(ready == 3);
    REQUIRE_THROWS_WITH(openDataset((kData / "frames.xml").string(), {}),
                        Catch::Contains("Metashape cameras.xml") && Catch::Contains("give --depth PATTERN"));
}

TEST_CASE("Metashape cameras.xml: what cannot be read is refused with its line")
{
    const fs::path dir = scratch("refusals");
    const auto refused = [&](const std::string& name, const std::string& text, const std::string& what) {
        INFO(name);
        const std::string path = writeText(dir / name, text);
        REQUIRE_THROWS_WITH(readCameraSet(path, &cameraFormatNamed("metashape")),
                            Catch::Contains("Metashape cameras file '" + path + "'") && Catch::Contains(what));
    };
    refused("short.xml", documentWith(cameraElement(0, "", "1 0 0 0 0 1 0 0 0 0 1 -3 0 0 0")), "holds 15 numbers; it takes 16");
    refused("nan.xml", documentWith(cameraElement(0, "", "1 0 0 0 0 1 0 0 0 0 1 nan 0 0 0 1")), "'nan', not a finite number");
    refused("both.xml",
            documentWith(cameraElement(0, " component_id=\"0\""),
                         "    <components><component id=\"0\"><transform><scale>2</scale></transform></component></components>\n"
                         "    <transform><scale>3</scale></transform>\n"),
            "which one places the camera is not defined");
    refused("scale.xml", documentWith(cameraElement(0), "    <transform><scale>0</scale></transform>\n"), "must be a positive number");
    refused("photoscan.xml", documentWith(cameraElement(0), "", "          <fx>50</fx>\n"), "PhotoScan's older model");
    refused("sensor.xml",
            [] {
                std::string text = documentWith(cameraElement(0));
                text.replace(text.find("sensor_id=\"0\""), 13, "sensor_id=\"7\"");
                return text;
            }(),
            "names sensor 7");
    refused("root.xml", "<?xml version=\"1.0\"?>\n<calibration><f>5</f></calibration>\n", "the root element must be <document>");
    refused("sheared.xml", documentWith(cameraElement(0, "", "1 0.5 0 0 0 1 0 0 0 0 1 -3 0 0 0 1")), "IMG_0.JPG");

    // A camera with skew (b2) is kept with its refusal, as one with distortion is.
    const std::string skewed = writeText(dir / "skew.xml", documentWith(cameraElement(0), "", "          <b2>0.5</b2>\n"));
    const CameraSet set = readCameraSet(skewed);
    REQUIRE_THAT(set.cameras.at(0).refusal, Catch::Contains("skew"));
    // b1 is an affinity: fx = f + b1.
    const std::string affine = writeText(dir / "b1.xml", documentWith(cameraElement(0), "", "          <b1>2</b1>\n"));
    const CameraSpec spec = readCameraSet(affine).cameras.at(0).spec;
    const PinholeIntrinsics k = pinholeIntrinsicsOf(Camera(spec), 0.5);
    REQUIRE(k.fx == Approx(52).margin(1e-12));
    REQUIRE(k.fy == Approx(50).margin(1e-12));
    REQUIRE(k.cx == Approx(32).margin(1e-12));
    // Without a chunk or component transform the pose is the chunk's, and the camera says so.
    REQUIRE_THAT(spec.notes.at(0), Catch::Contains("internal coordinates"));
}

TEST_CASE("Metashape cameras.xml: a file of 4,000 cameras (1.3 MB) is read whole")
{
    std::string cameras;
    for (int i = 0; i < 4000; ++i)
        cameras += cameraElement(i, "", "0.99999999999999989 0 0 0 0 1 0 0 0 0 1 -3.0000000000000004 0 0 0 1") +
                   "      <!-- what a real export carries beside the pose: -->\n"
                   "      <!-- <rotation_covariance>1.2e-06 0 0 0 1.2e-06 0 0 0 1.2e-06</rotation_covariance> -->\n"
                   "      <!-- <location_covariance>4.4e-04 0 0 0 4.4e-04 0 0 0 4.4e-04</location_covariance> -->\n";
    const fs::path dir = scratch("large");
    const std::string path = writeText(dir / "cameras.xml", documentWith(cameras));
    REQUIRE(fs::file_size(path) > (std::size_t(1) << 20));
    const CameraSet set = readCameraSet(path);
    REQUIRE(set.cameras.size() == 4000);
    REQUIRE(set.cameras[3999].name == "IMG_3999.JPG");
}
