// COLMAP models (format_colmap.cpp) against hand-computed projections of a known point: text
// and binary twins, FILE#FRAME selection, and broken models refused with the file and the line
// or record.
#include "camera_test_support.h"
#include "zcheck/camera_formats.h"
#include "zcheck/camera_import.h"
#include "zcheck/dataset_source.h"
#include "zcheck/error.h"
#include "zcheck/pose.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <utility>
#include <vector>

using namespace zcheck;
using namespace zcheck::testing;

namespace {

const char* kCamerasTxt = "# Camera list with one line of data per camera:\n"
                          "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
                          "# Number of cameras: 3\n"
                          "1 PINHOLE 640 480 500 400 330 250\n"
                          "2 SIMPLE_RADIAL 320 240 300 160 120 0\n"
                          "3 OPENCV 640 480 500 500 320 240 0.1 0 0 0\n";

std::string imagesTxt()
{
    char line[512];
    std::snprintf(line, sizeof line,
                  "# Image list with two lines of data per image:\n"
                  "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
                  "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
                  "1 %.17g 0 %.17g 0 0.1 -0.2 3 1 images/img_000.png\n"
                  "10.5 20.5 -1\n"
                  "2 1 0 0 0 0 0 5 2 images/img_001.png\n"
                  "\n"
                  "3 1 0 0 0 0 0 5 3 img_002.png\n"
                  "\n",
                  kH, kH);
    return line;
}

void putU32(std::string& out, std::uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); }
void putI32(std::string& out, std::int32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); }
void putU64(std::string& out, std::uint64_t v) { out.append(reinterpret_cast<const char*>(&v), 8); }
void putF64(std::string& out, double v) { out.append(reinterpret_cast<const char*>(&v), 8); }

// The same model as COLMAP's binary files (layout as in cameras/src/format_colmap.cpp's header).
void writeBinaryModel(const fs::path& dir)
{
    std::string cameras;
    putU64(cameras, 3);
    putU32(cameras, 1), putI32(cameras, 1), putU64(cameras, 640), putU64(cameras, 480);
    for (double p : {500.0, 400.0, 330.0, 250.0}) putF64(cameras, p);
    putU32(cameras, 2), putI32(cameras, 2), putU64(cameras, 320), putU64(cameras, 240);
    for (double p : {300.0, 160.0, 120.0, 0.0}) putF64(cameras, p);
    putU32(cameras, 3), putI32(cameras, 4), putU64(cameras, 640), putU64(cameras, 480);
    for (double p : {500.0, 500.0, 320.0, 240.0, 0.1, 0.0, 0.0, 0.0}) putF64(cameras, p);
    writeText(dir / "cameras.bin", cameras);

    std::string images;
    putU64(images, 3);
    auto image = [&](std::uint32_t id, const double (&q)[4], const double (&t)[3], std::uint32_t camera, const std::string& name,
                     int points) {
        putU32(images, id);
        for (double v : q) putF64(images, v);
        for (double v : t) putF64(images, v);
        putU32(images, camera);
        images += name;
        images += '\0';
        putU64(images, std::uint64_t(points));
        for (int k = 0; k < points; ++k) putF64(images, 10.5), putF64(images, 20.5), putU64(images, ~std::uint64_t(0));
    };
    image(1, {kH, 0, kH, 0}, {0.1, -0.2, 3}, 1, "images/img_000.png", 2);
    image(2, {1, 0, 0, 0}, {0, 0, 5}, 2, "images/img_001.png", 0);
    image(3, {1, 0, 0, 0}, {0, 0, 5}, 3, "img_002.png", 0);
    writeText(dir / "images.bin", images);
}

}  // namespace

TEST_CASE("a COLMAP text model projects a known point where the hand computation puts it", "[import][colmap]")
{
    const fs::path dir = scratch("colmap_text");
    writeText(dir / "cameras.txt", kCamerasTxt);
    writeText(dir / "images.txt", imagesTxt());
    REQUIRE(detectCameraFormat(dir.string()).name == "colmap");
    REQUIRE(detectCameraFormat((dir / "images.txt").string()).name == "colmap");
    const CameraSet set = readCameraSet(dir.string(), &cameraFormatNamed("colmap"));
    REQUIRE(set.cameras.size() == 3);
    REQUIRE(set.cameras[0].name == "images/img_000.png");
    REQUIRE_FALSE(set.cameras[0].hasClipPlanes);
    REQUIRE(set.cameras[0].spec.convention.name == "opencv");
    requireProjectsKnownPoint(set.cameras[0].spec, 0.5);
    // SIMPLE_RADIAL with k = 0 is a pinhole; a centred COLMAP camera has cx = W/2.
    REQUIRE(set.cameras[1].refusal.empty());
    REQUIRE(imagePointOf(set.cameras[1].spec, {0, 0, 0}).x == Approx(160).epsilon(1e-12));
    // OPENCV with k1 = 0.1 is the lens model opencv, its principal point moved to OpenCV's pixels.
    REQUIRE(set.cameras[2].refusal.empty());
    REQUIRE(set.find("img_002.png") == 2);
    const Camera opencv(set.cameras[2].spec);
    REQUIRE(opencv.lens());
    REQUIRE(opencv.lens()->spec().model == "opencv");
    const std::vector<double> params(opencv.lens()->spec().params.begin(), opencv.lens()->spec().params.begin() + 8);
    REQUIRE(params == std::vector<double>{500, 500, 319.5, 239.5, 0.1, 0, 0, 0});
}

TEST_CASE("a COLMAP binary model reads as its text twin", "[import][colmap]")
{
    const fs::path text = scratch("colmap_text2"), binary = scratch("colmap_binary");
    writeText(text / "cameras.txt", kCamerasTxt);
    writeText(text / "images.txt", imagesTxt());
    writeBinaryModel(binary);
    const CameraSet a = readCameraSet(text.string(), &cameraFormatNamed("colmap"));
    const CameraSet b = readCameraSet(binary.string(), &cameraFormatNamed("colmap"));
    REQUIRE(a.cameras.size() == b.cameras.size());
    for (std::size_t i = 0; i < a.cameras.size(); ++i) {
        REQUIRE(a.cameras[i].name == b.cameras[i].name);
        REQUIRE(a.cameras[i].refusal.empty() == b.cameras[i].refusal.empty());
        REQUIRE(Camera(a.cameras[i].spec).clipFromWorld == Camera(b.cameras[i].spec).clipFromWorld);
        REQUIRE(a.cameras[i].spec.projection.type == b.cameras[i].spec.projection.type);
        REQUIRE(a.cameras[i].spec.projection.lens == b.cameras[i].spec.projection.lens);
    }
    requireProjectsKnownPoint(b.cameras[0].spec, 0.5);
}

TEST_CASE("FILE#FRAME names a frame by index, name, path or stem, and says when it cannot", "[import]")
{
    const fs::path dir = scratch("colmap_select");
    writeText(dir / "cameras.txt", kCamerasTxt);
    writeText(dir / "images.txt", imagesTxt());
    const CameraSet set = readCameraSet(dir.string(), &cameraFormatNamed("colmap"));
    REQUIRE(set.find("0") == 0);
    REQUIRE(set.find("1") == 1);
    REQUIRE(set.find("images/img_001.png") == 1);
    REQUIRE(set.find("./images/img_001.png") == 1);
    REQUIRE(set.find("img_001.png") == 1);
    REQUIRE(set.find("img_001") == 1);
    REQUIRE_THROWS_WITH(set.find(""), Catch::Contains("holds 3 cameras") && Catch::Contains("FILE#FRAME"));
    REQUIRE_THROWS_WITH(set.find("img_099"), Catch::Contains("has no frame 'img_099'") && Catch::Contains("indices 0..2"));
    REQUIRE_THROWS_WITH(set.find("7"), Catch::Contains("has no frame '7'"));
    REQUIRE(splitCameraReference((dir.string() + "#img_001.png")) == std::pair{dir.string(), std::string("img_001.png")});
    REQUIRE(splitCameraReference(dir.string()) == std::pair{dir.string(), std::string()});
}

TEST_CASE("broken COLMAP models are refused with the file and the line or record", "[import][colmap][validation]")
{
    const fs::path dir = scratch("colmap_broken");
    writeText(dir / "images.txt", imagesTxt());
    auto refuses = [&](const std::string& cameras, const std::string& what) {
        writeText(dir / "cameras.txt", cameras);
        INFO(cameras);
        REQUIRE_THROWS_WITH(readCameraSet(dir.string(), &cameraFormatNamed("colmap")), Catch::Contains(what));
    };
    refuses("1 PINHOLE 640 480 500 400 330\n",
            "line 1: camera model PINHOLE takes 4 parameters, the line has 3 (PINHOLE: fx, fy, cx, cy)");
    refuses("1 PINHOL 640 480 500 400 330 250\n", "line 1: unknown camera model 'PINHOL'");
    refuses("1 PINHOLE 640 480 500 nan 330 250\n", "line 1: parameter 2 'nan' is not a finite number");
    refuses("1 PINHOLE 640.5 480 500 400 330 250\n", "WIDTH '640.5' is not an integer");
    refuses("1 PINHOLE 16385 480 500 400 330 250\n", "line 1: WIDTH '16385' is not an integer in 1..16384");
    refuses("2 PINHOLE 640 480 500 400 330 250\n", "CAMERA_ID 1 is not in the model's cameras");
    refuses("1 PINHOLE 640 480 500 400 330 250\n1 PINHOLE 640 480 500 400 330 250\n", "line 2: CAMERA_ID 1 appears twice");

    // Binary: truncated and lying counts, refused before anything is allocated.
    const fs::path bin = scratch("colmap_broken_bin");
    writeBinaryModel(bin);
    std::string cameras;
    {
        std::ifstream in(bin / "cameras.bin", std::ios::binary);
        cameras.assign(std::istreambuf_iterator<char>(in), {});
    }
    writeText(bin / "cameras.bin", cameras.substr(0, cameras.size() - 4));
    REQUIRE_THROWS_WITH(readCameraSet(bin.string(), &cameraFormatNamed("colmap")), Catch::Contains("cut short"));
    std::string lying = cameras;
    const std::uint64_t huge = std::uint64_t(1) << 60;
    std::memcpy(lying.data(), &huge, 8);
    writeText(bin / "cameras.bin", lying);
    REQUIRE_THROWS_WITH(readCameraSet(bin.string(), &cameraFormatNamed("colmap")), Catch::Contains("more than its"));
    std::string badModel = cameras;
    const std::int32_t model = 99;
    std::memcpy(badModel.data() + 12, &model, 4);
    writeText(bin / "cameras.bin", badModel);
    REQUIRE_THROWS_WITH(readCameraSet(bin.string(), &cameraFormatNamed("colmap")), Catch::Contains("model id 99"));
    // A side one past Camera::kMaxImageSide (width: the u64 after the count, the id and the model).
    std::string wide = cameras;
    const std::uint64_t width = 16385;
    std::memcpy(wide.data() + 16, &width, 8);
    writeText(bin / "cameras.bin", wide);
    REQUIRE_THROWS_WITH(readCameraSet(bin.string(), &cameraFormatNamed("colmap")), Catch::Contains("outside 1..16384 per side"));
}


// ---- camera models (lens models) -------------------------------------------------------

namespace {

constexpr double kPi = 3.14159265358979323846;

bool hasOneFocal(const std::string& model)
{
    for (const char* name : {"SIMPLE_PINHOLE", "SIMPLE_RADIAL", "RADIAL", "SIMPLE_RADIAL_FISHEYE", "RADIAL_FISHEYE",
                             "SIMPLE_DIVISION", "SIMPLE_FISHEYE"})
        if (model == name) return true;
    return false;
}

// COLMAP's ImgFromCam, model by model, written out by hand from src/colmap/sensor/models.h (the
// models' Distortion, ImgFromFisheye and FisheyeFromNormal): camera-frame direction d to COLMAP's
// pixel (x, y), whose origin is the image's top-left corner — zcheck's image coordinates.
glm::dvec2 colmapImgFromCam(const std::string& model, const std::vector<double>& p, const glm::dvec3& d)
{
    if (model == "EQUIRECTANGULAR") {  // w, h: azimuth from +z, elevation up (−y)
        const double azimuth = std::atan2(d.x, d.z), elevation = std::atan2(-d.y, std::hypot(d.x, d.z));
        return {(azimuth / (2 * kPi) + 0.5) * p[0], (0.5 - elevation / kPi) * p[1]};
    }
    const std::size_t focals = hasOneFocal(model) ? 1 : 2;
    const double f1 = p[0], f2 = p[focals - 1], c1 = p[focals], c2 = p[focals + 1];
    const double* k = p.data() + focals + 2;  // the extra parameters, in COLMAP's order
    const double u = d.x / d.z, v = d.y / d.z, r2 = u * u + v * v;
    glm::dvec2 m;  // what f and c map to pixels
    if (model == "SIMPLE_PINHOLE" || model == "PINHOLE") {
        m = {u, v};
    } else if (model == "SIMPLE_RADIAL") {  // f, cx, cy, k
        m = glm::dvec2(u, v) * (1 + k[0] * r2);
    } else if (model == "RADIAL") {  // f, cx, cy, k1, k2
        m = glm::dvec2(u, v) * (1 + k[0] * r2 + k[1] * r2 * r2);
    } else if (model == "OPENCV" || model == "FULL_OPENCV") {  // k1, k2, p1, p2 (, k3, k4, k5, k6)
        double radial = 1 + k[0] * r2 + k[1] * r2 * r2;
        if (model == "FULL_OPENCV")
            radial = (radial + k[4] * r2 * r2 * r2) / (1 + k[5] * r2 + k[6] * r2 * r2 + k[7] * r2 * r2 * r2);
        m = {u * radial + 2 * k[2] * u * v + k[3] * (r2 + 2 * u * u), v * radial + 2 * k[3] * u * v + k[2] * (r2 + 2 * v * v)};
    } else if (model == "FOV") {  // omega: r ↦ atan(2r·tan(ω/2))/ω (Devernay–Faugeras)
        const double r = std::sqrt(r2), omega = k[0];
        m = glm::dvec2(u, v) * (std::atan(2 * r * std::tan(omega / 2)) / (r * omega));
    } else if (model == "SIMPLE_DIVISION" || model == "DIVISION") {  // k: the root of k·ρ·s² − z·s + ρ = 0
        const double rho = std::hypot(d.x, d.y);
        m = glm::dvec2(d.x, d.y) * (2 / (d.z + std::sqrt(d.z * d.z - 4 * rho * rho * k[0])));
    } else if (model == "EUCM") {  // alpha, beta
        const double den = k[0] * std::sqrt(k[1] * (d.x * d.x + d.y * d.y) + d.z * d.z) + (1 - k[0]) * d.z;
        m = glm::dvec2(d.x, d.y) / den;
    } else {  // the fisheyes: the equidistant point e = (u, v)·atan(r)/r, |e| = θ, then their distortion
        const double r = std::sqrt(r2);
        const glm::dvec2 e = glm::dvec2(u, v) * (std::atan(r) / r);
        const double t2 = glm::dot(e, e), t4 = t2 * t2, t6 = t4 * t2, t8 = t4 * t4;
        if (model == "SIMPLE_FISHEYE" || model == "FISHEYE") {
            m = e;
        } else if (model == "SIMPLE_RADIAL_FISHEYE") {
            m = e * (1 + k[0] * t2);
        } else if (model == "RADIAL_FISHEYE") {
            m = e * (1 + k[0] * t2 + k[1] * t4);
        } else if (model == "OPENCV_FISHEYE") {  // k1..k4
            m = e * (1 + k[0] * t2 + k[1] * t4 + k[2] * t6 + k[3] * t8);
        } else if (model == "THIN_PRISM_FISHEYE") {  // k1, k2, p1, p2, k3, k4, sx1, sy1, all on e
            const double radial = 1 + k[0] * t2 + k[1] * t4 + k[4] * t6 + k[5] * t8;
            m = {e.x * radial + 2 * k[2] * e.x * e.y + k[3] * (t2 + 2 * e.x * e.x) + k[6] * t2,
                 e.y * radial + 2 * k[3] * e.x * e.y + k[2] * (t2 + 2 * e.y * e.y) + k[7] * t2};
        } else if (model == "RAD_TAN_THIN_PRISM_FISHEYE") {  // k0..k5, p0, p1, s0..s3 on q = e·radial
            double radial = 1, power = 1;
            for (int i = 0; i < 6; ++i) power *= t2, radial += k[i] * power;
            const glm::dvec2 q = e * radial;
            const double s2 = glm::dot(q, q);
            m = {q.x + 2 * k[7] * q.x * q.y + k[6] * (s2 + 2 * q.x * q.x) + k[8] * s2 + k[9] * s2 * s2,
                 q.y + 2 * k[6] * q.x * q.y + k[7] * (s2 + 2 * q.y * q.y) + k[10] * s2 + k[11] * s2 * s2};
        } else {
            FAIL("no hand formula for " << model);
        }
    }
    return {f1 * m.x + c1, f2 * m.y + c2};
}

struct ModelCase {
    std::string model;
    int width, height;
    std::vector<double> params;  // as cameras.txt has them
    const char* lens;            // the zcheck lens model expected
};

// Every model the reader knows with distortion, coefficients a real lens might have: none folds
// inside its 640×480 image.
const std::vector<ModelCase>& modelCases()
{
    static const std::vector<ModelCase> cases = {
        {"SIMPLE_RADIAL", 640, 480, {500, 320, 240, -0.08}, "opencv"},
        {"RADIAL", 640, 480, {500, 320, 240, -0.08, 0.01}, "opencv"},
        {"OPENCV", 640, 480, {500, 480, 321, 238, -0.08, 0.01, 0.001, -0.002}, "opencv"},
        {"FULL_OPENCV", 640, 480, {500, 480, 321, 238, -0.08, 0.01, 0.001, -0.002, 0.003, 0.02, -0.01, 0.004}, "opencv"},
        {"OPENCV_FISHEYE", 640, 480, {300, 310, 322, 238, 0.02, -0.01, 0.003, -0.0005}, "opencv_fisheye"},
        {"FOV", 640, 480, {500, 480, 321, 238, 0.8}, "fov"},
        {"SIMPLE_RADIAL_FISHEYE", 640, 480, {300, 322, 238, 0.02}, "opencv_fisheye"},
        {"RADIAL_FISHEYE", 640, 480, {300, 322, 238, 0.02, -0.004}, "opencv_fisheye"},
        {"THIN_PRISM_FISHEYE", 640, 480, {300, 310, 322, 238, 0.02, -0.01, 0.001, -0.002, 0.003, -0.0005, 0.0008, -0.0006},
         "thin_prism_fisheye"},
        {"RAD_TAN_THIN_PRISM_FISHEYE", 640, 480,
         {300, 310, 322, 238, 0.02, -0.01, 0.003, -0.0005, 0.0001, -0.00002, 0.001, -0.002, 0.0008, -0.0003, -0.0006, 0.0002},
         "fisheye624"},
        {"SIMPLE_DIVISION", 640, 480, {500, 320, 240, -0.1}, "division"},
        {"DIVISION", 640, 480, {500, 480, 321, 238, 0.05}, "division"},
        {"SIMPLE_FISHEYE", 640, 480, {300, 322, 238}, "opencv_fisheye"},
        {"FISHEYE", 640, 480, {300, 310, 322, 238}, "opencv_fisheye"},
        {"EUCM", 640, 480, {300, 310, 322, 238, 0.6, 1.1}, "eucm"},
        {"EQUIRECTANGULAR", 1024, 512, {1024, 512}, "equirectangular"},
    };
    return cases;
}

std::string numbers(const std::vector<double>& values)
{
    std::string out;
    for (double v : values) {
        char text[40];
        std::snprintf(text, sizeof text, "%.17g", v);
        out += std::string(out.empty() ? "" : " ") + text;
    }
    return out;
}

// A COLMAP text model of the cases, camera i + 1 seen by image i + 1 ("cam_<MODEL>.png") from
// the world origin (qvec identity, tvec 0), so camera frame = world.
void writeCasesText(const fs::path& dir, const std::vector<ModelCase>& cases)
{
    std::string cameras = "# Camera list with one line of data per camera:\n", images;
    for (std::size_t i = 0; i < cases.size(); ++i) {
        const ModelCase& c = cases[i];
        cameras += std::to_string(i + 1) + " " + c.model + " " + std::to_string(c.width) + " " + std::to_string(c.height) +
                   " " + numbers(c.params) + "\n";
        images += std::to_string(i + 1) + " 1 0 0 0 0 0 0 " + std::to_string(i + 1) + " cam_" + c.model + ".png\n\n";
    }
    writeText(dir / "cameras.txt", cameras);
    writeText(dir / "images.txt", images);
}

// The same as COLMAP's binary files (layout in format_colmap.cpp's header): model ids from
// models.h's CameraModelId.
void writeCasesBinary(const fs::path& dir, const std::vector<std::pair<int, ModelCase>>& cases)
{
    std::string cameras, images;
    putU64(cameras, cases.size());
    putU64(images, cases.size());
    for (std::size_t i = 0; i < cases.size(); ++i) {
        const auto& [id, c] = cases[i];
        putU32(cameras, std::uint32_t(i + 1)), putI32(cameras, id), putU64(cameras, std::uint64_t(c.width)),
            putU64(cameras, std::uint64_t(c.height));
        for (double p : c.params) putF64(cameras, p);
        putU32(images, std::uint32_t(i + 1));
        for (double q : {1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0}) putF64(images, q);
        putU32(images, std::uint32_t(i + 1));
        images += "cam_" + c.model + ".png";
        images += '\0';
        putU64(images, 0);
    }
    writeText(dir / "cameras.bin", cameras);
    writeText(dir / "images.bin", images);
}

// Directions in the camera frame inside every case's field (z > 0; the last two wide, for the
// fisheyes and the panorama).
const std::vector<glm::dvec3> kDirections = {{0.3, 0.1, 1}, {-0.25, 0.2, 1}, {0.1, -0.35, 1}, {0.42, -0.31, 1}};
const std::vector<glm::dvec3> kWideDirections = {{1.2, -0.5, 1}, {-0.9, 0.8, 0.7}};

bool isWide(const std::string& model)
{
    return model.find("FISHEYE") != std::string::npos || model == "EUCM" || model == "EQUIRECTANGULAR";
}

void requireProjectsAsColmap(const ModelCase& c, const CameraSpec& spec)
{
    INFO(c.model);
    const Camera camera(spec);
    REQUIRE(camera.lens());
    REQUIRE(camera.lens()->spec().model == c.lens);
    std::vector<glm::dvec3> directions = kDirections;
    if (isWide(c.model)) directions.insert(directions.end(), kWideDirections.begin(), kWideDirections.end());
    for (const glm::dvec3& d : directions) {
        INFO("direction " << d.x << " " << d.y << " " << d.z);
        const std::optional<glm::dvec2> got = camera.lens()->imageFromDirection(d);
        REQUIRE(got);
        requireNear(*got, colmapImgFromCam(c.model, c.params, d));
        // and back: the pixel's ray is the direction
        const std::optional<glm::dvec3> ray = camera.lens()->directionFromImage(*got);
        REQUIRE(ray);
        REQUIRE(glm::length(*ray - glm::normalize(d)) < 1e-9);
    }
}

CameraSpec lensCamera(const LensSpec& lens, int width, int height)
{
    CameraSpec spec;
    spec.convention = Convention::preset("opencv");
    spec.width = width, spec.height = height;
    spec.projection.type = ProjectionType::NonLinear;
    spec.projection.lens = lens;
    spec.projection.near = 0.1, spec.projection.far = 50;
    spec.view = View::lookAt({1.5, -2, 4}, {0.1, 0.2, -0.5}, {0.1, -1, 0});
    return spec;
}

}  // namespace

TEST_CASE("each COLMAP camera model projects as models.h's formula, text and binary", "[import][colmap][lens]")
{
    const fs::path dir = scratch("colmap_models");
    writeCasesText(dir, modelCases());
    const CameraSet set = readCameraSet(dir.string(), &cameraFormatNamed("colmap"));
    REQUIRE(set.cameras.size() == modelCases().size());
    for (std::size_t i = 0; i < modelCases().size(); ++i) {
        REQUIRE(set.cameras[i].refusal.empty());
        requireProjectsAsColmap(modelCases()[i], set.cameras[i].spec);
    }

    // The parameters as zcheck's lens models hold them: COLMAP's order, fx = fy = f for the
    // one-focal models, the principal point ½ px nearer the corner (OpenCV's pixel centres).
    const auto lensOf = [&](std::size_t i) { return Camera(set.cameras[i].spec).lens()->spec(); };
    const auto head = [&](std::size_t i, std::size_t n) {
        const std::vector<double>& p = lensOf(i).params;
        return std::vector<double>(p.begin(), p.begin() + std::ptrdiff_t(n));
    };
    REQUIRE(head(0, 6) == std::vector<double>{500, 500, 319.5, 239.5, -0.08, 0});                // SIMPLE_RADIAL
    REQUIRE(head(3, 12) == std::vector<double>{500, 480, 320.5, 237.5, -0.08, 0.01, 0.001, -0.002, 0.003, 0.02, -0.01,
                                               0.004});                                             // FULL_OPENCV
    REQUIRE(head(7, 6) == std::vector<double>{300, 300, 321.5, 237.5, 0.02, -0.004});              // RADIAL_FISHEYE
    REQUIRE(head(12, 8) == std::vector<double>{300, 300, 321.5, 237.5, 0, 0, 0, 0});               // SIMPLE_FISHEYE
    REQUIRE(lensOf(15) == LensSpec{"equirectangular", {-180, 180, -90, 90}});
    // The axis lands on COLMAP's principal point: (cx, cy) counted from the image's corner.
    requireNear(*Camera(set.cameras[13].spec).lens()->imageFromDirection({0, 0, 1}), {322, 238});  // FISHEYE
    // Straight back is the panorama's left (and right) edge, straight up its top row.
    REQUIRE(Camera(set.cameras[15].spec).lens()->imageFromDirection({0, -1, 1e-300})->y == Approx(0).margin(1e-9));

    // Binary: the same cameras by model id (models.h's CameraModelId: OPENCV_FISHEYE 5,
    // FULL_OPENCV 6, RAD_TAN_THIN_PRISM_FISHEYE 11, EQUIRECTANGULAR 17).
    std::vector<std::pair<int, ModelCase>> binaryCases;
    for (const auto& [id, index] : {std::pair{5, 4}, {6, 3}, {11, 9}, {17, 15}})
        binaryCases.push_back({id, modelCases()[std::size_t(index)]});
    const fs::path bin = scratch("colmap_models_bin");
    writeCasesBinary(bin, binaryCases);
    const CameraSet binary = readCameraSet(bin.string(), &cameraFormatNamed("colmap"));
    REQUIRE(binary.cameras.size() == binaryCases.size());
    for (std::size_t i = 0; i < binaryCases.size(); ++i) {
        REQUIRE(binary.cameras[i].refusal.empty());
        requireProjectsAsColmap(binaryCases[i].second, binary.cameras[i].spec);
    }
    REQUIRE(binary.cameras[0].spec.projection.lens == set.cameras[4].spec.projection.lens);
    REQUIRE(binary.cameras[2].spec.projection.lens == set.cameras[9].spec.projection.lens);
}

TEST_CASE("COLMAP models whose distortion is nothing are linear pinholes, fisheyes stay fisheyes", "[import][colmap][lens]")
{
    const fs::path dir = scratch("colmap_linear");
    const std::vector<ModelCase> cases = {
        {"SIMPLE_RADIAL", 640, 480, {500, 320, 240, 0}, ""},
        {"FULL_OPENCV", 640, 480, {500, 480, 321, 238, 0, 0, 0, 0, 0, 0, 0, 0}, ""},
        {"FOV", 640, 480, {500, 480, 321, 238, 0}, ""},  // ω → 0 is the pinhole (COLMAP's own limit)
        {"DIVISION", 640, 480, {500, 480, 321, 238, 0}, ""},
        {"EUCM", 640, 480, {500, 480, 321, 238, 0, 2.5}, ""},  // α = 0: (x, y)/z whatever β
        {"OPENCV_FISHEYE", 640, 480, {300, 310, 322, 238, 0, 0, 0, 0}, "opencv_fisheye"},
        {"FOV", 640, 480, {500, 480, 321, 238, -0.8}, "fov"},  // even in ω: |ω|
    };
    writeCasesText(dir, cases);
    const CameraSet set = readCameraSet(dir.string(), &cameraFormatNamed("colmap"));
    for (std::size_t i = 0; i < 5; ++i) {
        INFO(cases[i].model);
        REQUIRE(set.cameras[i].spec.projection.type == ProjectionType::Pinhole);
        const std::vector<double>& p = cases[i].params;
        const std::size_t c = hasOneFocal(cases[i].model) ? 1 : 2;  // where cx is
        const glm::dvec2 expected = colmapImgFromCam("PINHOLE", {p[0], p[c - 1], p[c], p[c + 1]}, {0.3, 0.1, 1});
        requireNear(imagePointOf(set.cameras[i].spec, {0.3, 0.1, 1}), expected);
    }
    REQUIRE(set.cameras[5].spec.projection.type == ProjectionType::NonLinear);
    REQUIRE(set.cameras[5].spec.projection.lens.model == "opencv_fisheye");
    REQUIRE(set.cameras[6].spec.projection.lens.params.at(4) == 0.8);
    requireNear(*Camera(set.cameras[6].spec).lens()->imageFromDirection({0.3, 0.1, 1}),
                colmapImgFromCam("FOV", {500, 480, 321, 238, -0.8}, {0.3, 0.1, 1}));
}

TEST_CASE("a COLMAP model mixing pinhole, fisheye and unreadable cameras keeps the unreadable one's refusal only",
          "[import][colmap][lens][dataset]")
{
    const fs::path dir = scratch("colmap_mixed");
    writeText(dir / "cameras.txt", "1 PINHOLE 640 480 500 400 330 250\n"
                                   "2 OPENCV_FISHEYE 640 480 300 310 322 238 0.02 -0.01 0.003 -0.0005\n"
                                   "3 EQUIRECTANGULAR 1024 512 2048 1024\n"
                                   "4 OPENCV 640 480 500 500 320 240 -1 0 0 0\n");
    writeText(dir / "images.txt", "1 1 0 0 0 0 0 0 1 a.png\n\n2 1 0 0 0 0 0 0 2 b.png\n\n"
                                  "3 1 0 0 0 0 0 0 3 c.png\n\n4 1 0 0 0 0 0 0 4 d.png\n\n");
    const CameraSet set = readCameraSet(dir.string(), &cameraFormatNamed("colmap"));
    REQUIRE(set.cameras.size() == 4);
    REQUIRE(set.cameras[0].refusal.empty());
    REQUIRE(set.cameras[1].refusal.empty());
    REQUIRE_FALSE(Camera(set.cameras[set.find("a.png")].spec).lens());
    REQUIRE(Camera(set.cameras[set.find("b.png")].spec).lens()->spec().model == "opencv_fisheye");
    // EQUIRECTANGULAR's w, h are the size its mapping spans: not this image's.
    REQUIRE_THAT(set.cameras[2].refusal,
                 Catch::Contains("images.txt line 5 uses COLMAP cameras.txt line 3 (camera 3): camera model EQUIRECTANGULAR "
                                 "has w = 2048, h = 1024 for an image of 1024x512"));
    REQUIRE_THROWS_WITH(set.find("c.png"), Catch::Contains("would not span this image"));
    // A lens that folds inside its image (k1 = −1: r(1 − r²) turns back at r = 0.58, 192 px from
    // the principal point, 240 px from the nearest edge).
    REQUIRE_THAT(set.cameras[3].refusal, Catch::Contains("cameras.txt line 4 (camera 4): camera model OPENCV: lens model "
                                                         "opencv folds (is no longer one-to-one)"));
    REQUIRE_THAT(set.cameras[3].refusal, Catch::Contains("inside the image"));

    DatasetSourceOptions options;
    options.cameraFormat = &cameraFormatNamed("colmap");
    options.depthPattern = "depth/{stem}.bin";
    const Dataset dataset = openDataset(dir.string(), options);
    REQUIRE(dataset.frames.size() == 4);
    REQUIRE(dataset.frames[0].error.empty());
    REQUIRE(dataset.frames[1].error.empty());
    REQUIRE_THAT(dataset.frames[2].error, Catch::Contains("EQUIRECTANGULAR"));
    REQUIRE_THAT(dataset.frames[3].error, Catch::Contains("folds"));
}

TEST_CASE("COLMAP camera models out of zcheck's reach or malformed are refused with the line and the rule",
          "[import][colmap][lens][validation]")
{
    const fs::path dir = scratch("colmap_lens_broken");
    writeText(dir / "images.txt", "1 1 0 0 0 0 0 0 1 a.png\n\n");
    auto read = [&](const std::string& cameras) {
        writeText(dir / "cameras.txt", cameras);
        return readCameraSet(dir.string(), &cameraFormatNamed("colmap"));
    };
    auto throws = [&](const std::string& cameras, const std::string& what) {
        INFO(cameras);
        REQUIRE_THROWS_WITH(read(cameras), Catch::Contains(what));
    };
    auto refused = [&](const std::string& cameras, const std::string& what) {
        INFO(cameras);
        const CameraSet set = read(cameras);
        REQUIRE_THAT(set.cameras.at(0).refusal, Catch::Contains(what));
        REQUIRE_THROWS_WITH(set.find("a.png"), Catch::Contains(what));
    };
    throws("1 OPENCV_FISHEYE 640 480 300 300 320 240 0.1 0 0\n",
           "line 1: camera model OPENCV_FISHEYE takes 8 parameters, the line has 7 "
           "(OPENCV_FISHEYE: fx, fy, cx, cy, k1, k2, k3, k4)");
    throws("1 RAD_TAN_THIN_PRISM_FISHEYE 640 480 300 300 320 240 0 0 0 0 0 0 0 0 0 0 0\n",
           "takes 16 parameters, the line has 15");
    throws("1 EQUIRECTANGULAR 1024 512 1024\n",
           "camera model EQUIRECTANGULAR takes 2 parameters, the line has 1 (EQUIRECTANGULAR: w, h)");
    throws("1 EUCM 640 480 300 300 320 240 0.5 inf\n", "parameter 6 'inf' is not a finite number");
    throws("1 SIMPLE_FISHEYE 640 480 -300 320 240\n",
           "line 1 (camera 1): intrinsics: the focal length fx must be a positive finite number of pixels, got -300");
    refused("1 EQUIRECTANGULAR 1024 512 1024 1024\n", "has w = 1024, h = 1024 for an image of 1024x512");
    refused("1 EUCM 640 480 300 300 320 240 0.5 0\n", "camera model EUCM: lens model eucm: 'beta' must be > 0, got 0");
    refused("1 FOV 640 480 300 300 320 240 4\n", "camera model FOV: lens model fov: 'omega' must lie in (0, π), got 4");
    refused("1 SIMPLE_RADIAL 640 480 500 320 240 -1\n", "lens model opencv folds");

    // Binary: EQUIRECTANGULAR's id is 17; 18 is no model.
    const fs::path bin = scratch("colmap_lens_broken_bin");
    writeCasesBinary(bin, {{17, {"EQUIRECTANGULAR", 1024, 512, {1024, 256}, "equirectangular"}}});
    REQUIRE_THAT(readCameraSet(bin.string(), &cameraFormatNamed("colmap")).cameras.at(0).refusal,
                 Catch::Contains("COLMAP cameras.bin camera 1: camera model EQUIRECTANGULAR has w = 1024, h = 256"));
    writeCasesBinary(bin, {{18, {"PINHOLE", 640, 480, {500, 500, 320, 240}, ""}}});
    REQUIRE_THROWS_WITH(readCameraSet(bin.string(), &cameraFormatNamed("colmap")),
                        Catch::Contains("has model id 18, which zcheck does not know (COLMAP's 0..17"));
}

TEST_CASE("a lens camera written as COLMAP reads back as the same lens, or is refused naming the model",
          "[import][colmap][lens][roundtrip]")
{
    // Principal points with few bits, so that adding ½ and taking it away again is exact.
    const std::vector<std::pair<LensSpec, const char*>> writable = {
        {{"opencv", {500, 480, 319.5, 239.25, -0.08, 0.01, 0.001, -0.002}}, "OPENCV"},
        {{"opencv", {500, 480, 319.5, 239.25, -0.08, 0.01, 0.001, -0.002, 0.003, 0.02, -0.01, 0.004}}, "FULL_OPENCV"},
        {{"opencv_fisheye", {300, 310, 321.5, 237.75, 0.02, -0.01, 0.003, -0.0005}}, "OPENCV_FISHEYE"},
        {{"thin_prism_fisheye", {300, 310, 321.5, 237.75, 0.02, -0.01, 0.001, -0.002, 0.003, -0.0005, 0.0008, -0.0006}},
         "THIN_PRISM_FISHEYE"},
        {{"fisheye624",
          {300, 310, 321.5, 237.75, 0.02, -0.01, 0.003, -0.0005, 0.0001, -0.00002, 0.001, -0.002, 0.0008, -0.0003, -0.0006,
           0.0002}},
         "RAD_TAN_THIN_PRISM_FISHEYE"},
        {{"fov", {500, 480, 320.5, 237.5, 0.8}}, "FOV"},
        {{"division", {500, 480, 320.5, 237.5, 0.05}}, "DIVISION"},
        {{"eucm", {300, 310, 321.5, 237.75, 0.6, 1.1}}, "EUCM"},
        {{"equirectangular", {-180, 180, -90, 90}}, "EQUIRECTANGULAR"},
    };
    const fs::path dir = scratch("colmap_lens_roundtrip");
    for (const auto& [lens, model] : writable) {
        INFO(lens.model << " as " << model);
        const bool panorama = lens.model == "equirectangular";
        const Camera camera(lensCamera(lens, 640, panorama ? 320 : 480));
        const auto files = cameraInFormat(camera, cameraFormatNamed("colmap"), "frame_7.png");
        REQUIRE(files.at(0).fileName == "cameras.txt");
        const std::string line = std::string("\n1 ") + model + " 640 " + (panorama ? "320 640 320\n" : "480 ");
        REQUIRE_THAT(files[0].text, Catch::Contains(line));
        for (const CameraFileText& f : files) writeText(dir / f.fileName, f.text);
        const CameraSet set = readCameraSet(dir.string(), &cameraFormatNamed("colmap"));
        REQUIRE(set.cameras.at(0).refusal.empty());
        const Camera back(set.cameras[0].spec);
        REQUIRE(back.lens());
        REQUIRE(back.lens()->spec() == camera.lens()->spec());
        for (int r = 0; r < 4; ++r)
            for (int c = 0; c < 4; ++c) REQUIRE(back.eyeFromWorld[c][r] == Approx(camera.eyeFromWorld[c][r]).margin(1e-12));
    }
    // A COLMAP principal point is ½ px further from the corner than the lens's: cx = W/2 centred.
    {
        const Camera centred(lensCamera({"opencv_fisheye", {300, 300, 319.5, 239.5}}, 640, 480));
        REQUIRE_THAT(cameraInFormat(centred, cameraFormatNamed("colmap"), "x")[0].text,
                     Catch::Contains("\n1 OPENCV_FISHEYE 640 480 300 300 320 240 0 0 0 0\n"));
    }
    // brown_conrady without k4 is OpenCV's (its k3 the r⁶ term of FULL_OPENCV), Metashape's without
    // skew OpenCV's with fx = f + b1 and the tangential pair swapped: the same projection.
    const std::vector<std::pair<LensSpec, std::string>> equivalent = {
        {{"brown_conrady", {500, 480, 319.5, 239.25, -0.08, 0.01, 0.003, 0, 0.001, -0.002}},
         "\n1 FULL_OPENCV 640 480 500 480 320 239.75 -0.080000000000000002 0.01 0.001 -0.002 0.0030000000000000001 0 0 0\n"},
        {{"brown_conrady", {500, 480, 319.5, 239.25, -0.08, 0.01, 0, 0, 0.001, -0.002}},
         "\n1 OPENCV 640 480 500 480 320 239.75 -0.080000000000000002 0.01 0.001 -0.002\n"},
        {{"metashape_frame", {500, 319.5, 239.25, 4, 0, -0.08, 0.01, 0.003, 0, 0.001, -0.002}},
         "\n1 FULL_OPENCV 640 480 504 500 320 239.75 -0.080000000000000002 0.01 -0.002 0.001 0.0030000000000000001 0 0 0\n"},
        {{"metashape_fisheye", {300, 319.5, 239.25, -2, 0, 0.02, -0.01, 0.003, -0.0005}},
         "\n1 OPENCV_FISHEYE 640 480 298 300 320 239.75 0.02 -0.01 0.0030000000000000001 -0.00050000000000000001\n"},
        {{"metashape_fisheye", {300, 319.5, 239.25, -2, 0, 0.02, -0.01, 0.003, -0.0005, 0.001, -0.002}},
         "\n1 THIN_PRISM_FISHEYE 640 480 298 300 320 239.75 0.02 -0.01 -0.002 0.001 0.0030000000000000001 "
         "-0.00050000000000000001 0 0\n"},
    };
    for (const auto& [lens, line] : equivalent) {
        INFO(lens.model);
        const Camera camera(lensCamera(lens, 640, 480));
        const auto files = cameraInFormat(camera, cameraFormatNamed("colmap"), "frame_7.png");
        REQUIRE_THAT(files[0].text, Catch::Contains(line));
        for (const CameraFileText& f : files) writeText(dir / f.fileName, f.text);
        const Camera back(readCameraSet(dir.string(), &cameraFormatNamed("colmap")).cameras.at(0).spec);
        std::vector<glm::dvec3> directions = kDirections;
        directions.insert(directions.end(), kWideDirections.begin(), kWideDirections.end());
        for (const glm::dvec3& d : directions) {
            const std::optional<glm::dvec2> expected = camera.lens()->imageFromDirection(d);
            if (!expected) continue;  // beyond a perspective lens's field
            requireNear(*back.lens()->imageFromDirection(d), *expected);
        }
    }

    const auto refuses = [](const LensSpec& lens, const std::string& what) {
        INFO(lens.model);
        const Camera camera(lensCamera(lens, 640, lens.model == "equirectangular" ? 320 : 480));
        REQUIRE_THROWS_WITH(cameraInFormat(camera, cameraFormatNamed("colmap"), "x"), Catch::Contains(what));
    };
    refuses({"opencv", {500, 480, 319.5, 239.5, -0.08, 0.01, 0, 0, 0, 0, 0, 0, 0.001}},
            "cannot write lens model opencv as a COLMAP camera: s1 = 0.001: COLMAP's OPENCV and FULL_OPENCV have no "
            "thin prism");
    refuses({"opencv", {500, 480, 319.5, 239.5, -0.08, 0.01, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0.01}}, "tau_y = 0.01");
    refuses({"brown_conrady", {500, 480, 319.5, 239.5, -0.08, 0.01, 0, 0.0001}},
            "cannot write lens model brown_conrady as a COLMAP camera: k4 = 0.0001");
    refuses({"double_sphere", {300, 300, 319.5, 239.5, 0.2, 0.6}},
            "cannot write lens model double_sphere as a COLMAP camera: COLMAP has no camera model of its formula");
    refuses({"unified", {300, 300, 319.5, 239.5, 0.8}}, "lens model unified");
    refuses({"metashape_frame", {500, 319.5, 239.5, 0, 0.5, 0.01}},
            "cannot write lens model metashape_frame as a COLMAP camera: b2 = 0.5: COLMAP's models have no skew");
    refuses({"metashape_frame", {500, 319.5, 239.5, 0, 0, 0.01, 0, 0, 0.0001}},
            "metashape_frame as a COLMAP camera: k4 = 0.0001");
    refuses({"equisolid", {300, 300, 319.5, 239.5}}, "lens model equisolid");
    refuses({"equirectangular", {-90, 90, -45, 45}},
            "spans longitude -90..90° and latitude -45..45°; COLMAP's EQUIRECTANGULAR spans the whole sphere");
}
