// COLMAP models (format_colmap.cpp) against hand-computed projections of a known point: text
// and binary twins, FILE#FRAME selection, and broken models refused with the file and the line
// or record.
#include "camera_test_support.h"
#include "zcheck/camera_formats.h"
#include "zcheck/camera_import.h"
#include "zcheck/error.h"
#include "zcheck/pose.h"

#include <catch2/catch.hpp>

#include <cstdint>
#include <cstring>
#include <string>

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
    // OPENCV with k1 = 0.1 is kept, refused by name.
    REQUIRE_THAT(set.cameras[2].refusal, Catch::Contains("camera model OPENCV has lens distortion (k1 = 0.1, k2 = 0, p1 = 0, p2 = 0)"));
    REQUIRE_THAT(set.cameras[2].refusal, Catch::Contains("zcheck checks linear projections"));
    REQUIRE_THROWS_WITH(set.find("img_002.png"), Catch::Contains("lens distortion"));
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
    refuses("1 PINHOLE 640 480 500 400 330\n", "line 1: camera model PINHOLE takes 4 parameters, the line has 3");
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

