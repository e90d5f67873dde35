// Metashape's cameras.xml (format_metashape.cpp) against poses and projections computed
// independently with numpy from the same XML (tests/data/metashape/expected.py, whose notes
// cite the sources for each convention, and which writes out the manual's frame and fisheye
// camera models): the 1.x layout (chunk transform) and the 2.x layout (component transform) of
// one scene with a pinhole, a distorted frame, a fisheye and a spherical sensor, the refusals,
// and a file of 4,000 cameras.
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

// The pixel (top-left pixel's centre at 0.5, 0.5) of a world point through a lens camera.
glm::dvec2 lensPixel(const CameraSpec& spec, const glm::dvec3& world)
{
    const Camera camera(spec);
    const glm::dvec4 eye = camera.eyeFromWorld * glm::dvec4(world, 1.0);
    const std::optional<glm::dvec2> pixel = camera.lens()->imageFromDirection(camera.lensFrameFromEye(glm::dvec3(eye)));
    REQUIRE(pixel);
    return *pixel;
}

// A minimal file: one sensor (a frame camera of 64x48, f 50, unless given), the chunk transform
// given, cameras as given.
std::string documentWith(const std::string& cameras, const std::string& chunkExtra = "", const std::string& calibration = "",
                         const std::string& sensor = "")
{
    const std::string frame = "      <sensor id=\"0\" label=\"s\" type=\"frame\">\n"
                              "        <resolution width=\"64\" height=\"48\"/>\n"
                              "        <calibration type=\"frame\" class=\"adjusted\">\n"
                              "          <resolution width=\"64\" height=\"48\"/>\n          <f>50</f>\n" +
                              calibration + "        </calibration>\n      </sensor>\n";
    return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<document version=\"1.5.0\">\n  <chunk label=\"c\">\n"
           "    <sensors next_id=\"1\">\n" +
           (sensor.empty() ? frame : sensor) + "    </sensors>\n    <cameras>\n" + cameras + "    </cameras>\n" +
           chunkExtra + "  </chunk>\n</document>\n";
}

std::string cameraElement(int id, const std::string& extra = "", const std::string& transform = "1 0 0 0 0 1 0 0 0 0 1 -3 0 0 0 1")
{
    return "      <camera id=\"" + std::to_string(id) + "\" sensor_id=\"0\" label=\"IMG_" + std::to_string(id) + ".JPG\"" +
           extra + ">\n        <transform>" + transform + "</transform>\n      </camera>\n";
}

}  // namespace

TEST_CASE("Metashape cameras.xml: poses, intrinsics and lenses as numpy computes them, in the 1.x and 2.x layouts")
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
            if (reason == "sensor_type")  // a cylindrical sensor
                REQUIRE_THAT(found->refusal, Catch::Contains("is a cylindrical camera") &&
                                                 Catch::Contains("frame, fisheye and spherical sensors"));
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
            const nlohmann::json& lens = want["lens"];
            if (lens.is_null()) {
                REQUIRE(spec.projection.type == ProjectionType::Pinhole);
            } else {  // the lens model and its parameters exactly (cx, cy: W/2 + cx − ½, OpenCV's pixels)
                REQUIRE(spec.projection.type == ProjectionType::NonLinear);
                REQUIRE(spec.projection.lens.model == lens["model"].get<std::string>());
                REQUIRE(spec.projection.lens.params == lens["params"].get<std::vector<double>>());
            }
            const Camera camera(spec);
            for (const nlohmann::json& probe : want["projections"]) {
                const glm::dvec3 world{probe["world"][0].get<double>(), probe["world"][1].get<double>(),
                                       probe["world"][2].get<double>()};
                const glm::dvec2 pixel = lens.is_null() ? projected(spec, world).first : lensPixel(spec, world);
                const double depth = (camera.eyeFromWorld * glm::dvec4(world, 1.0)).z;
                REQUIRE(pixel.x == Approx(probe["pixel"][0].get<double>()).margin(1e-9));
                REQUIRE(pixel.y == Approx(probe["pixel"][1].get<double>()).margin(1e-9));
                REQUIRE(depth == Approx(probe["depth"].get<double>()).margin(1e-12));
            }
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
    REQUIRE(ready == 6);  // the usable cameras of expected.json: three pinholes, a frame, a fisheye, a sphere
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

TEST_CASE("Metashape cameras.xml: the manual's camera models by hand, and what no lens model has")
{
    const fs::path dir = scratch("lenses");
    const auto read = [&](const std::string& name, const std::string& text) {
        return readCameraSet(writeText(dir / name, text), &cameraFormatNamed("metashape")).cameras.at(0);
    };
    // The camera sits at (0, 0, −3) looking along +z (camera axes = world axes), so the world
    // point (0.2, −0.1, 1) is (X, Y, Z) = (0.2, −0.1, 4): x = X/Z = 0.05, y = Y/Z = −0.025.
    const glm::dvec3 world{0.2, -0.1, 1};
    const double x = 0.05, y = -0.025, r2 = x * x + y * y;

    SECTION("skew b2 alone: a metashape_frame lens, u = W/2 + cx + x'(f + b1) + y'·b2")
    {
        const ImportedCamera camera = read("skew.xml", documentWith(cameraElement(0), "", "          <b2>0.5</b2>\n"));
        REQUIRE(camera.refusal.empty());
        REQUIRE(camera.spec.projection.lens ==
                LensSpec{"metashape_frame", {50, 31.5, 23.5, 0, 0.5, 0, 0, 0, 0, 0, 0}});  // cx: 64/2 + 0 − ½
        const glm::dvec2 pixel = lensPixel(camera.spec, world);
        REQUIRE(pixel.x == Approx(32 + x * 50 + y * 0.5).margin(1e-12));
        REQUIRE(pixel.y == Approx(24 + y * 50).margin(1e-12));
    }
    SECTION("P1 goes with r² + 2x² in the x equation (OpenCV's p2), and b1 adds to f in x only")
    {
        const ImportedCamera camera = read(
            "p1.xml", documentWith(cameraElement(0), "",
                                   "          <cx>1.25</cx>\n          <cy>-0.5</cy>\n          <b1>2</b1>\n"
                                   "          <k1>0.1</k1>\n          <k4>0.02</k4>\n          <p1>0.01</p1>\n"
                                   "          <p2>-0.004</p2>\n"));
        REQUIRE(camera.spec.projection.lens.model == "metashape_frame");
        const double radial = 1 + 0.1 * r2 + 0.02 * r2 * r2 * r2 * r2;
        const double xd = x * radial + 0.01 * (r2 + 2 * x * x) + 2 * -0.004 * x * y;
        const double yd = y * radial + -0.004 * (r2 + 2 * y * y) + 2 * 0.01 * x * y;
        const glm::dvec2 pixel = lensPixel(camera.spec, world);
        REQUIRE(pixel.x == Approx(32 + 1.25 + xd * 50 + xd * 2).margin(1e-12));
        REQUIRE(pixel.y == Approx(24 - 0.5 + yd * 50).margin(1e-12));
    }
    SECTION("a fisheye sensor is metashape_fisheye, an equidistant fisheye even without coefficients")
    {
        const std::string sensor = "      <sensor id=\"0\" label=\"s\" type=\"fisheye\">\n"
                                   "        <resolution width=\"64\" height=\"48\"/>\n"
                                   "        <calibration type=\"fisheye\" class=\"adjusted\">\n"
                                   "          <resolution width=\"64\" height=\"48\"/>\n          <f>20</f>\n"
                                   "        </calibration>\n      </sensor>\n";
        const ImportedCamera camera = read("fisheye.xml", documentWith(cameraElement(0), "", "", sensor));
        REQUIRE(camera.spec.projection.lens == LensSpec{"metashape_fisheye", {20, 31.5, 23.5, 0, 0, 0, 0, 0, 0, 0, 0}});
        // x0 = X/Z, r0 = |(x0, y0)|, (x, y) = (x0, y0)·atan(r0)/r0; u = W/2 + x·f, v = H/2 + y·f
        const double r0 = std::sqrt(r2), scale = std::atan(r0) / r0;
        const glm::dvec2 pixel = lensPixel(camera.spec, world);
        REQUIRE(pixel.x == Approx(32 + x * scale * 20).margin(1e-12));
        REQUIRE(pixel.y == Approx(24 + y * scale * 20).margin(1e-12));
        // 80° off the axis, beyond any pinhole: θ·f from the centre
        const double theta = 80 * M_PI / 180;
        const glm::dvec2 far = lensPixel(camera.spec, glm::dvec3(std::tan(theta) * 4, 0, 1));
        REQUIRE(far.x == Approx(32 + theta * 20).margin(1e-9));
    }
    SECTION("a spherical sensor is the whole sphere: longitude atan2(X, Z) from the centre column, the top row up")
    {
        const auto spherical = [](const std::string& size, const std::string& calibration) {
            return "      <sensor id=\"0\" label=\"s\" type=\"spherical\">\n        <resolution " + size + "/>\n" +
                   calibration + "      </sensor>\n";
        };
        const ImportedCamera camera =
            read("sphere.xml", documentWith(cameraElement(0), "", "", spherical("width=\"128\" height=\"64\"", "")));
        REQUIRE(camera.refusal.empty());
        REQUIRE(camera.spec.projection.lens == LensSpec{"equirectangular", {-180, 180, -90, 90}});
        REQUIRE(camera.spec.width == 128);
        // Straight right (+X): longitude 90°, a quarter of the width right of the centre.
        const glm::dvec2 right = lensPixel(camera.spec, glm::dvec3(1, 0, -3));
        REQUIRE(right.x == Approx(64 + 128 * 0.25).margin(1e-12));
        REQUIRE(right.y == Approx(32).margin(1e-12));
        // Up (−Y) 45° ahead: latitude 45°, a quarter of the height above the centre row.
        const glm::dvec2 up = lensPixel(camera.spec, glm::dvec3(0, -1, -2));
        REQUIRE(up.x == Approx(64).margin(1e-12));
        REQUIRE(up.y == Approx(32 - 64 * 0.25).margin(1e-12));
        // Behind, a little left: the left edge's side of the seam.
        const glm::dvec2 behind = lensPixel(camera.spec, glm::dvec3(-0.01, 0, -4));
        REQUIRE(behind.x == Approx(64 + 128 * std::atan2(-0.01, -1.0) / (2 * M_PI)).margin(1e-12));
        // A calibration that is the sphere's own (f = H/π) is the same sphere; any other is refused.
        char f[64];
        std::snprintf(f, sizeof f, "%.17g", 64 / M_PI);
        const std::string own = std::string("        <calibration type=\"spherical\" class=\"adjusted\">\n          <f>") +
                                f + "</f>\n        </calibration>\n";
        REQUIRE(read("own.xml", documentWith(cameraElement(0), "", "", spherical("width=\"128\" height=\"64\"", own)))
                    .spec.projection.lens == LensSpec{"equirectangular", {-180, 180, -90, 90}});
        const std::string other = "        <calibration type=\"spherical\" class=\"adjusted\">\n          <f>20</f>\n"
                                  "          <cx>3</cx>\n        </calibration>\n";
        REQUIRE_THAT(read("other.xml", documentWith(cameraElement(0), "", "", spherical("width=\"128\" height=\"64\"", other)))
                         .refusal,
                     Catch::Contains("sensor 0 (spherical, line 5)") && Catch::Contains("gives f = 20") &&
                         Catch::Contains("f = H/π"));
        REQUIRE_THAT(read("wide.xml", documentWith(cameraElement(0), "", "", spherical("width=\"100\" height=\"64\"", "")))
                         .refusal,
                     Catch::Contains("is 100x64") && Catch::Contains("2:1"));
    }
    SECTION("refused, with the sensor's line: p3, p4; a lens that folds inside the image; other sensor types")
    {
        const ImportedCamera p3 = read("p3.xml", documentWith(cameraElement(0), "", "          <p3>0.001</p3>\n"));
        REQUIRE_THAT(p3.refusal, Catch::Contains("sensor 0 (calibration, line 7) has p3 = 0.001") &&
                                     Catch::Contains("1 + P3·r² + P4·r⁴"));
        const std::string folds = writeText(dir / "folds.xml", documentWith(cameraElement(0), "", "          <k1>-5</k1>\n"));
        const CameraSet set = readCameraSet(folds);
        REQUIRE_THAT(set.cameras.at(0).refusal, Catch::Contains("Metashape cameras file '" + folds + "': sensor 0 "
                                                                "(calibration, line 7): lens model metashape_frame folds"));
        REQUIRE_THROWS_WITH(set.find("IMG_0.JPG"), Catch::Contains("folds"));
        const std::string rpc = "      <sensor id=\"0\" label=\"s\" type=\"rpc\">\n        <resolution width=\"64\" "
                                "height=\"48\"/>\n      </sensor>\n";
        REQUIRE_THAT(read("rpc.xml", documentWith(cameraElement(0), "", "", rpc)).refusal,
                     Catch::Contains("sensor 0 (line 5) is a rpc camera: zcheck reads Metashape's frame, fisheye and "
                                     "spherical sensors"));
    }
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
