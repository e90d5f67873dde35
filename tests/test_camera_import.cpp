// Camera importers (camera_import.h, camera_sources.h) against hand-computed projections of
// known points, each format's pixel-centre and axis conventions, FILE#FRAME selection, the
// refusals, and round trips through the writers (camera_export.h).
#include "zcheck/camera_formats.h"
#include "zcheck/camera_import.h"
#include "zcheck/camera_sources.h"
#include "zcheck/error.h"
#include "zcheck/mesh_loader.h"
#include "zcheck/pose.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <unistd.h>

using namespace zcheck;
namespace fs = std::filesystem;

namespace {

fs::path scratch(const std::string& name)
{
    const fs::path dir = fs::temp_directory_path() / ("zcheck_import_" + std::to_string(::getpid())) / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

void writeText(const fs::path& path, const std::string& text)
{
    std::ofstream(path, std::ios::binary) << text;
}

glm::dvec2 imagePointOf(const CameraSpec& spec, const glm::dvec3& pWorld)
{
    const Camera camera(spec);
    const glm::dvec4 pClip = camera.clipFromWorld * glm::dvec4(pWorld, 1.0);
    const glm::dvec4 pWindow = camera.windowFromNdc * (pClip / pClip.w);
    return {pWindow.x, camera.imageYFromWindowY(pWindow.y)};
}

// The test's world point and a COLMAP-style pose: qvec 90° about y, tvec (0.1, −0.2, 3), so the
// point lands at p_cam = (0.3, 0.1, 3.4) (test_pose.cpp does the arithmetic).
const glm::dvec3 kPoint{-0.4, 0.3, 0.2};
const double kH = std::sqrt(0.5);

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

// The same model as COLMAP's binary files (layout as in import_colmap.cpp's header).
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

void requireNear(const glm::dvec2& actual, const glm::dvec2& expected)
{
    REQUIRE(actual.x == Approx(expected.x).margin(1e-9));
    REQUIRE(actual.y == Approx(expected.y).margin(1e-9));
}

void requireProjectsKnownPoint(const CameraSpec& spec, double pixelCenter)
{
    // K = (fx 500, fy 400, cx 330, cy 250) in coordinates whose top-left pixel centre is
    // `pixelCenter`: u = 500·0.3/3.4 + 330, v = 400·0.1/3.4 + 250 there, image x = u + 0.5 − pixelCenter.
    const glm::dvec2 pImage = imagePointOf(spec, kPoint);
    REQUIRE(pImage.x == Approx(500 * 0.3 / 3.4 + 330 + 0.5 - pixelCenter).epsilon(1e-12));
    REQUIRE(pImage.y == Approx(400 * 0.1 / 3.4 + 250 + 0.5 - pixelCenter).epsilon(1e-12));
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

TEST_CASE("a nerfstudio transforms.json is camera-to-world in OpenGL axes with centres at +0.5", "[import][nerfstudio]")
{
    // The pose of the COLMAP test, stored as nerfstudio stores it: world-from-camera, OpenGL axes.
    const glm::dmat3 r = rotationFromQuaternion(kH, 0, kH, 0, "q");
    glm::dmat4 camFromWorld(r);
    camFromWorld[3] = glm::dvec4(0.1, -0.2, 3, 1);
    const glm::dmat4 c2w = rigidInverse(camFromWorld) * eyeFromEye(Convention::preset("opencv"), Convention::preset("opengl"));
    std::string rows;
    for (int row = 0; row < 4; ++row) {
        rows += row ? ", [" : "[";
        for (int c = 0; c < 4; ++c) {
            char v[40];
            std::snprintf(v, sizeof v, "%.17g", c2w[c][row]);
            rows += (c ? ", " : "") + std::string(v);
        }
        rows += "]";
    }
    const fs::path dir = scratch("nerfstudio");
    writeText(dir / "transforms.json",
              R"({"camera_model": "OPENCV", "fl_x": 500, "fl_y": 400, "cx": 330, "cy": 250, "w": 640.0, "h": 480,
                  "k1": 0, "k2": 0, "p1": 0, "p2": 0,
                  "frames": [{"file_path": "images/frame_00001.png", "depth_file_path": "depths/frame_00001.png",
                              "transform_matrix": [)" + rows + R"(]},
                             {"file_path": "images/frame_00002.png", "k1": 0.02, "transform_matrix": [)" + rows + R"(]}]})");
    REQUIRE(detectCameraFormat((dir / "transforms.json").string()).name == "nerfstudio");
    const CameraSet set = readCameraSet((dir / "transforms.json").string(), &cameraFormatNamed("nerfstudio"));
    REQUIRE(set.cameras.size() == 2);
    REQUIRE(set.cameras[0].spec.convention.name == "opengl");
    REQUIRE(set.cameras[0].depthPath == (dir / "depths/frame_00001.png").string());
    requireProjectsKnownPoint(set.cameras[0].spec, 0.5);
    REQUIRE(set.find("frame_00001") == 0);
    REQUIRE_THAT(set.cameras[1].refusal, Catch::Contains("camera model OPENCV has lens distortion (k1 = 0.02"));
}

TEST_CASE("an instant-ngp transforms.json without an image size takes the depth map's", "[import][nerfstudio]")
{
    const fs::path dir = scratch("ngp");
    writeText(dir / "transforms.json",
              R"({"camera_angle_x": 0.6911112070083618,
                  "frames": [{"file_path": "./train/r_0", "transform_matrix": [[1,0,0,0],[0,1,0,0],[0,0,1,4],[0,0,0,1]]}]})");
    const CameraSet set = readCameraSet((dir / "transforms.json").string(), &cameraFormatNamed("nerfstudio"));
    const ImportedCamera& camera = set.cameras.at(set.find("r_0"));
    REQUIRE_FALSE(camera.hasImageSize);
    REQUIRE(camera.projectionForSize);
    // NeRF-synthetic's lego: 800x800, fl = 0.5·800/tan(0.5·0.6911112) = 1111.111 px, cx = 400.
    const Projection p = camera.projectionForSize(800, 800);
    REQUIRE(p.fx == Approx(1111.1110311937682).epsilon(1e-9));
    REQUIRE(p.fy == Approx(p.fx));
    REQUIRE(p.cx == Approx(399.5));  // OpenCV's coordinates: 400 − 0.5
}

TEST_CASE("OpenCV FileStorage YAML and XML put the top-left pixel centre at 0 and hold a world-to-camera pose", "[import][opencv]")
{
    const fs::path dir = scratch("opencv");
    // K with cx, cy in OpenCV coordinates: 329.5, 249.5 are the COLMAP test's 330, 250.
    writeText(dir / "calib.yml", "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\n"
                                 "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
                                 "   data: [ 500., 0., 329.5, 0.,\n       400., 249.5, 0., 0., 1. ]\n"
                                 "distortion_coefficients: !!opencv-matrix\n   rows: 5\n   cols: 1\n   dt: d\n"
                                 "   data: [ 0., 0., 0., 0., 0. ]\n"
                                 "R: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: [ 0, 0, 1, 0, 1, 0, -1, 0, 0 ]\n"
                                 "T: !!opencv-matrix\n   rows: 3\n   cols: 1\n   dt: d\n   data: [ 0.1, -0.2, 3. ]\n");
    REQUIRE(detectCameraFormat((dir / "calib.yml").string()).name == "opencv");
    const CameraSet yaml = readCameraSet((dir / "calib.yml").string(), &cameraFormatNamed("opencv"));
    requireProjectsKnownPoint(yaml.cameras.at(yaml.find("")).spec, 0.5);

    writeText(dir / "calib.xml", "<?xml version=\"1.0\"?>\n<opencv_storage>\n<image_width>640</image_width>\n"
                                 "<image_height>480</image_height>\n<camera_matrix type_id=\"opencv-matrix\">\n"
                                 "  <rows>3</rows>\n  <cols>3</cols>\n  <dt>d</dt>\n  <data>\n"
                                 "    500. 0. 329.5 0. 400. 249.5 0. 0. 1.</data></camera_matrix>\n"
                                 "<rvec type_id=\"opencv-matrix\"><rows>3</rows><cols>1</cols><dt>d</dt><data>0 1.5707963267948966 0</data></rvec>\n"
                                 "<tvec type_id=\"opencv-matrix\"><rows>3</rows><cols>1</cols><dt>d</dt><data>0.1 -0.2 3</data></tvec>\n"
                                 "</opencv_storage>\n");
    REQUIRE(detectCameraFormat((dir / "calib.xml").string()).name == "opencv");
    const CameraSet xml = readCameraSet((dir / "calib.xml").string(), &cameraFormatNamed("opencv"));
    requireProjectsKnownPoint(xml.cameras.at(0).spec, 0.5);  // rvec: 90° about y, as the quaternion

    // A repeated element would let one value hide another: refused, as YAML's repeated keys are.
    writeText(dir / "twice.xml", "<?xml version=\"1.0\"?>\n<opencv_storage>\n<image_width>640</image_width>\n"
                                 "<image_width>320</image_width>\n</opencv_storage>\n");
    REQUIRE_THROWS_WITH(readCameraSet((dir / "twice.xml").string(), &cameraFormatNamed("opencv")),
                        Catch::Contains("line 4: the element <image_width> is repeated inside <opencv_storage>"));

    // Without a pose the camera's own frame is the world, and the report says so.
    writeText(dir / "intrinsics.yml", "%YAML:1.0\nimage_width: 640\nimage_height: 480\n"
                                      "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
                                      "   data: [ 500., 0., 319.5, 0., 500., 239.5, 0., 0., 1. ]\n");
    const CameraSet bare = readCameraSet((dir / "intrinsics.yml").string(), &cameraFormatNamed("opencv"));
    requireNear(imagePointOf(bare.cameras[0].spec, {0, 0, 2}), glm::dvec2(320, 240));
    REQUIRE_THAT(bare.cameras[0].spec.notes.at(0), Catch::Contains("has no pose"));
}

TEST_CASE("OpenCV's stereo files: intrinsics.yml#left and #right, the right posed by R and T of extrinsics.yml beside it",
          "[import][opencv]")
{
    const fs::path dir = scratch("opencv_stereo");
    auto mat = [](const std::string& name, int rows, int cols, const std::string& data) {
        return name + ": !!opencv-matrix\n   rows: " + std::to_string(rows) + "\n   cols: " + std::to_string(cols) +
               "\n   dt: d\n   data: [ " + data + " ]\n";
    };
    // As stereo_calib.cpp writes them: no image size; D1 and D2 of 8 (here zero).
    writeText(dir / "intrinsics.yml", "%YAML:1.0\n" + mat("M1", 3, 3, "500, 0, 319.5, 0, 500, 239.5, 0, 0, 1") +
                                          mat("D1", 1, 8, "0, 0, 0, 0, 0, 0, 0, 0") +
                                          mat("M2", 3, 3, "510, 0, 330, 0, 505, 241, 0, 0, 1") +
                                          mat("D2", 1, 8, "0, 0, 0, 0, 0, 0, 0, 0"));
    // R: 5° about y; T: the right camera 0.12 to the right (x_right = R·x_left + T).
    const double a = glm::radians(5.0), c = std::cos(a), s = std::sin(a);
    writeText(dir / "extrinsics.yml", "%YAML:1.0\n" +
                                          mat("R", 3, 3, std::to_string(c) + ", 0, " + std::to_string(s) + ", 0, 1, 0, " +
                                                             std::to_string(-s) + ", 0, " + std::to_string(c)) +
                                          mat("T", 3, 1, "-0.12, 0, 0") + mat("R1", 3, 3, "1, 0, 0, 0, 1, 0, 0, 0, 1") +
                                          mat("P1", 3, 4, "500, 0, 320, 0, 0, 500, 240, 0, 0, 0, 1, 0") +
                                          mat("Q", 4, 4, "1, 0, 0, -320, 0, 1, 0, -240, 0, 0, 0, 500, 0, 0, 8.3, 0"));
    const CameraSet set = readCameraSet((dir / "intrinsics.yml").string(), &cameraFormatNamed("opencv"));
    const glm::dvec3 p(0.2, -0.1, 2.0);  // in the left camera's frame, the world
    const ImportedCamera& left = set.cameras.at(set.find("left"));
    REQUIRE(set.find("M1") == set.find("left"));
    REQUIRE_FALSE(left.hasImageSize);  // the depth map's size is taken (completeCamera)
    requireNear(imagePointOf(left.spec, p), glm::dvec2(500 * 0.1 + 319.5 + 0.5, 500 * -0.05 + 239.5 + 0.5));
    const ImportedCamera& right = set.cameras.at(set.find("right"));
    REQUIRE(set.find("M2") == set.find("right"));
    REQUIRE(right.refusal.empty());
    const glm::dvec3 q(c * p.x + s * p.z - 0.12, p.y, -s * p.x + c * p.z);  // R·p + T, by hand
    requireNear(imagePointOf(right.spec, p), glm::dvec2(510 * q.x / q.z + 330 + 0.5, 505 * q.y / q.z + 241 + 0.5));
    REQUIRE_THAT(right.spec.notes.at(0), Catch::Contains("extrinsics.yml") && Catch::Contains("R and T"));
    // A file without a #FRAME names neither: the reference must say which.
    REQUIRE_THROWS(set.find(""));
    // The extrinsics alone are no camera: refused, naming the intrinsics file's cameras.
    REQUIRE_THROWS_WITH(readCameraSet((dir / "extrinsics.yml").string(), &cameraFormatNamed("opencv")),
                        Catch::Contains("no camera matrix") && Catch::Contains("#left or FILE#right"));
    // Without extrinsics.yml beside it, the right camera has no pose: refused when asked for.
    const fs::path alone = scratch("opencv_stereo_alone");
    fs::copy_file(dir / "intrinsics.yml", alone / "intrinsics.yml");
    const CameraSet unposed = readCameraSet((alone / "intrinsics.yml").string(), &cameraFormatNamed("opencv"));
    REQUIRE_THROWS_WITH(unposed.find("right"), Catch::Contains("has no pose"));
    REQUIRE_NOTHROW(unposed.find("left"));
}

TEST_CASE("OpenCV's calibration.cpp file: each view's extrinsic_parameters a camera (#view_N), the file's own the default",
          "[import][opencv]")
{
    const fs::path dir = scratch("opencv_views");
    writeText(dir / "out_camera_data.yml",
              "%YAML:1.0\n---\nnr_of_frames: 2\nimage_width: 640\nimage_height: 480\n"
              "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: [ 500., 0., 319.5, 0., 500., 239.5, 0., 0., 1. ]\n"
              "distortion_coefficients: !!opencv-matrix\n   rows: 5\n   cols: 1\n   dt: d\n   data: [ 0., 0., 0., 0., 0. ]\n"
              "extrinsic_parameters: !!opencv-matrix\n   rows: 2\n   cols: 6\n   dt: d\n"
              "   data: [ 0., 0., 0., 0., 0., 2., 0., 0.3, 0., 0.1, 0.2, 3. ]\n");
    const CameraSet set = readCameraSet((dir / "out_camera_data.yml").string(), &cameraFormatNamed("opencv"));
    REQUIRE(set.cameras.size() == 3);
    REQUIRE(set.find("") == 0);  // the file's own camera, no pose
    const glm::dvec3 p(0.1, 0.05, 1.0);
    // view_1: rvec (0, 0.3, 0) — 0.3 rad about y — and tvec (0.1, 0.2, 3): x = R·p + t by hand.
    const double c = std::cos(0.3), s = std::sin(0.3);
    const glm::dvec3 x(c * p.x + s * p.z + 0.1, p.y + 0.2, -s * p.x + c * p.z + 3);
    requireNear(imagePointOf(set.cameras.at(set.find("view_1")).spec, p),
                glm::dvec2(500 * x.x / x.z + 320, 500 * x.y / x.z + 240));
    const glm::dvec3 x0(p.x, p.y, p.z + 2);  // view_0: no rotation, tvec (0, 0, 2)
    requireNear(imagePointOf(set.cameras.at(set.find("view_0")).spec, p),
                glm::dvec2(500 * x0.x / x0.z + 320, 500 * x0.y / x0.z + 240));
}

TEST_CASE("ROS CameraInfo: the calibration file and the echoed message, raw (K) and rectified (P)", "[import][ros]")
{
    const fs::path dir = scratch("ros");
    writeText(dir / "camera.yaml", "image_width: 640\nimage_height: 480\ncamera_name: depth_optical\n"
                                   "camera_matrix:\n  rows: 3\n  cols: 3\n  data: [500, 0, 319.5, 0, 500, 239.5, 0, 0, 1]\n"
                                   "distortion_model: plumb_bob\n"
                                   "distortion_coefficients:\n  rows: 1\n  cols: 5\n  data: [0, 0, 0, 0, 0]\n"
                                   "rectification_matrix:\n  rows: 3\n  cols: 3\n  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n"
                                   "projection_matrix:\n  rows: 3\n  cols: 4\n  data: [500, 0, 319.5, -25, 0, 500, 239.5, 0, 0, 0, 1, 0]\n");
    REQUIRE(detectCameraFormat((dir / "camera.yaml").string()).name == "ros");
    const CameraSet set = readCameraSet((dir / "camera.yaml").string(), &cameraFormatNamed("ros"));
    const ImportedCamera& raw = set.cameras.at(set.find(""));
    REQUIRE(raw.name == "raw");
    requireNear(imagePointOf(raw.spec, {0, 0, 2}), glm::dvec2(320, 240));
    // The rectified camera of a stereo pair's second camera: u = (fx·X + cx·Z + Tx)/Z.
    const ImportedCamera& rectified = set.cameras.at(set.find("rectified"));
    REQUIRE(imagePointOf(rectified.spec, {0, 0, 2}).x == Approx((500 * 0 + 319.5 * 2 - 25) / 2 + 0.5));

    writeText(dir / "message.yaml", "header:\n  stamp:\n    sec: 0\n    nanosec: 0\n  frame_id: camera_optical\n"
                                    "height: 480\nwidth: 640\ndistortion_model: plumb_bob\n"
                                    "d:\n- 0.1\n- 0.0\n- 0.0\n- 0.0\n- 0.0\n"
                                    "k:\n- 500.0\n- 0.0\n- 319.5\n- 0.0\n- 500.0\n- 239.5\n- 0.0\n- 0.0\n- 1.0\n"
                                    "r: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]\n"
                                    "p: [480.0, 0.0, 320.0, 0.0, 0.0, 480.0, 240.0, 0.0, 0.0, 0.0, 1.0, 0.0]\n"
                                    "binning_x: 0\nbinning_y: 0\nroi:\n  x_offset: 0\n  y_offset: 0\n  height: 0\n  width: 0\n"
                                    "  do_rectify: false\n---\n");
    const CameraSet message = readCameraSet((dir / "message.yaml").string(), &cameraFormatNamed("ros"));
    REQUIRE_THROWS_WITH(message.find(""), Catch::Contains("plumb_bob has lens distortion (k1 = 0.1") &&
                                              Catch::Contains("FILE#rectified"));
    requireNear(imagePointOf(message.cameras.at(message.find("rectified")).spec, {0, 0, 2}), glm::dvec2(320.5, 240.5));
}

TEST_CASE("glTF camera nodes: yfov and aspectRatio, the node's transform without its scale, zfar absent = infinite",
          "[import][gltf]")
{
    const fs::path dir = scratch("gltf");
    // A camera 5 units up +z looking down −z (its node's identity rotation), scaled by 2.
    writeText(dir / "cameras.gltf", R"({"asset": {"version": "2.0"},
        "cameras": [{"type": "perspective", "name": "main", "perspective": {"yfov": 0.7, "aspectRatio": 1.5, "znear": 0.1}},
                    {"type": "orthographic", "orthographic": {"xmag": 2, "ymag": 1, "znear": 0.5, "zfar": 50}}],
        "nodes": [{"name": "rig", "children": [1, 2], "translation": [0, 0, 5]},
                  {"name": "persp", "camera": 0, "scale": [2, 2, 2]},
                  {"camera": 1, "translation": [1, 0, 0]}],
        "scenes": [{"nodes": [0]}], "scene": 0})");
    REQUIRE(detectCameraFormat((dir / "cameras.gltf").string()).name == "gltf");
    const CameraSet set = readCameraSet((dir / "cameras.gltf").string());
    REQUIRE(set.cameras.size() == 2);
    REQUIRE(set.find("main") == 0);
    REQUIRE(set.find("persp") == 0);
    REQUIRE(set.find("nodes[2]") == 1);
    const ImportedCamera& persp = set.cameras[0];
    REQUIRE(persp.hasClipPlanes);
    REQUIRE_FALSE(persp.hasImageSize);
    REQUIRE(std::isinf(persp.spec.projection.far));
    CameraSpec spec = persp.spec;
    spec.width = 300, spec.height = 200;
    spec.projection = persp.projectionForSize(300, 200);
    // A point at (1, 0.5, 0): 5 in front. y_ndc = 0.5/(5·tan(0.35)), x_ndc = 1/(5·tan(0.35)·1.5).
    const glm::dvec2 p = imagePointOf(spec, {1, 0.5, 0});
    REQUIRE(p.x == Approx(150 + 150 * 1 / (5 * std::tan(0.35) * 1.5)));
    REQUIRE(p.y == Approx(100 - 100 * 0.5 / (5 * std::tan(0.35))));
    const ImportedCamera& ortho = set.cameras[1];
    CameraSpec o = ortho.spec;
    o.width = 400, o.height = 200;
    requireNear(imagePointOf(o, {2, 0.5, 0}), glm::dvec2(200 + 200 * 1.0 / 2, 100 - 100 * 0.5));
}

TEST_CASE("near and far hug the scene as the camera sees it", "[import][clip]")
{
    // Two squares across the view: at eye-z 4 (0.5 wide) and at eye-z 9; a third far behind the
    // camera and one off to the side do not count.
    Scene scene;
    scene.name = "squares";
    auto square = [&](double z, double half, double x = 0) {
        const auto base = std::uint32_t(scene.positions.size());
        for (auto [dx, dy] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}})
            scene.positions.emplace_back(float(x + dx * half), float(dy * half), float(z));
        scene.triangles.emplace_back(base, base + 1, base + 2);
        scene.triangles.emplace_back(base, base + 2, base + 3);
    };
    square(-4, 0.5), square(-9, 20), square(30, 1), square(-2, 0.5, 50);
    CameraSpec spec;
    spec.projection = Projection::perspective(60, kPlaceholderNear, kPlaceholderFar);
    spec.view = View::lookAt({0, 0, 0}, {0, 0, -1}, {0, 1, 0});
    const SceneNearFar planes = sceneNearFar(scene, spec);
    REQUIRE(planes.near == Approx(4 * 0.99));
    REQUIRE(planes.far == Approx(9 * 1.01));

    ImportedCamera imported;
    imported.name = "test";
    imported.spec = spec;
    const CameraSpec completed = completeCamera(imported, &scene, {});
    REQUIRE(completed.projection.near == Approx(3.96));
    REQUIRE_THAT(completed.notes.back(), Catch::Contains("near and far are not in the camera file"));
    const CameraSpec given = completeCamera(imported, &scene, {1.0, 50.0, std::nullopt, std::nullopt, std::nullopt});
    REQUIRE(given.projection.near == 1.0);
    REQUIRE(given.projection.far == 50.0);

    spec.view = View::lookAt({0, 0, 40}, {0, 0, 41}, {0, 1, 0});  // beyond them all, looking away
    REQUIRE_THROWS_WITH(sceneNearFar(scene, spec), Catch::Contains("sees none of scene 'squares'"));
}

TEST_CASE("a camera written as COLMAP, nerfstudio, OpenCV or zcheck reads back as the same camera", "[import][roundtrip]")
{
    CameraSpec spec;
    spec.convention = Convention::preset("vulkan");
    spec.width = 333, spec.height = 257;
    spec.projection.type = ProjectionType::Frustum;
    spec.projection.left = -0.03, spec.projection.right = 0.05, spec.projection.bottom = -0.02, spec.projection.top = 0.035;
    spec.projection.near = 0.1, spec.projection.far = 40;
    spec.view = View::lookAt({1.5, 2, 4}, {0.1, 0.2, -0.5}, {0.1, 1, 0});
    const Camera camera(spec);
    const fs::path dir = scratch("roundtrip");
    int written = 0;
    for (const CameraFormat* format : cameraFormats()) {  // every format with a writer, from the table
        if (!format->write) continue;
        ++written;
        INFO(format->name);
        const fs::path out = dir / format->name;
        fs::create_directories(out);
        const auto files = cameraInFormat(camera, *format, "frame_7.png");
        for (const CameraFileText& f : files) writeText(out / f.fileName, f.text);
        const std::string path = format->writesFolder ? out.string() : (out / files.front().fileName).string();
        REQUIRE(&detectCameraFormat(path) == format);
        const CameraSet set = readCameraSet(path, format);
        CameraSpec back = set.cameras.at(0).spec;
        back.projection.near = 0.1, back.projection.far = 40;
        REQUIRE(back.width == 333);
        for (const glm::dvec3 p : {glm::dvec3(0, 0, 0), glm::dvec3(0.5, -0.3, 1), glm::dvec3(-1, 1, -2)}) {
            const glm::dvec2 expected = imagePointOf(spec, p), got = imagePointOf(back, p);
            REQUIRE(got.x == Approx(expected.x).margin(1e-9));
            REQUIRE(got.y == Approx(expected.y).margin(1e-9));
        }
    }
    REQUIRE(written == 4);  // zcheck, colmap, nerfstudio, opencv
    spec.projection.type = ProjectionType::Orthographic;
    REQUIRE_THROWS_WITH(cameraInFormat(Camera(spec), cameraFormatNamed("colmap"), "x"), Catch::Contains("orthographic projection has no pinhole"));
}

namespace {

// The eye-z range of the scene's triangles clipped to a perspective camera's view, by brute force
// in eye space: every triangle, Sutherland–Hodgman against the four side planes through the eye
// and the near-window edges (left/right/top/bottom at eye-z = near) and the eye plane.
std::pair<double, double> bruteForceEyeZRange(const Scene& scene, const Camera& camera)
{
    const double n = camera.nearDistance();
    // Planes through the eye, ≥ 0 inside, in (image right, image up, forward) coordinates.
    auto inside = [&](const glm::dvec3& q, int plane) {
        switch (plane) {
        case 0: return q.x * n - camera.left() * q.z;
        case 1: return camera.right() * q.z - q.x * n;
        case 2: return q.y * n - camera.bottom() * q.z;
        case 3: return camera.top() * q.z - q.y * n;
        default: return q.z;
        }
    };
    const Convention& c = camera.convention();
    double lo = INFINITY, hi = -INFINITY;
    for (const glm::uvec3& t : scene.triangles) {
        std::vector<glm::dvec3> polygon;
        for (int k = 0; k < 3; ++k) {
            const glm::dvec3 e(camera.eyeFromWorld * glm::dvec4(glm::dvec3(scene.positions[t[k]]), 1.0));
            polygon.push_back({e.x, c.eyeUpY * e.y, c.eyeForwardZ * e.z});
        }
        for (int plane = 0; plane < 5 && !polygon.empty(); ++plane) {
            std::vector<glm::dvec3> next;
            for (std::size_t i = 0; i < polygon.size(); ++i) {
                const glm::dvec3 a = polygon[i], b = polygon[(i + 1) % polygon.size()];
                const double fa = inside(a, plane), fb = inside(b, plane);
                if (fa >= 0) next.push_back(a);
                if ((fa >= 0) != (fb >= 0)) next.push_back(a + (fa / (fa - fb)) * (b - a));
            }
            polygon = next;
        }
        for (const glm::dvec3& q : polygon) lo = std::min(lo, q.z), hi = std::max(hi, q.z);
    }
    return {lo, hi};
}

}  // namespace

TEST_CASE("near and far from the scene's triangle chunks equal a clip of every triangle", "[import][clip]")
{
    // A terrain seen from random places around and inside its bounds, in several conventions:
    // the chunk pruning must never change the answer.
    const Scene scene = loadScene("builtin:terrain?n=90");
    REQUIRE(scene.chunks);
    std::mt19937 random(17);
    std::uniform_real_distribution<double> along(-80, 80), up(2, 60);
    int seen = 0;
    for (int i = 0; i < 40; ++i) {
        CameraSpec spec;
        spec.convention = Convention::preset(Convention::presetNames()[std::size_t(i) % Convention::presetNames().size()]);
        spec.width = 160, spec.height = 120;
        spec.projection = Projection::perspective(30 + i, kPlaceholderNear, kPlaceholderFar);
        spec.view = View::lookAt({along(random), up(random), along(random)}, {along(random) / 4, 0, along(random) / 4}, {0, 1, 0});
        const auto [lo, hi] = bruteForceEyeZRange(scene, Camera(spec));
        if (!(hi > 0)) {
            REQUIRE_THROWS_WITH(sceneNearFar(scene, spec), Catch::Contains("sees none of scene"));
            continue;
        }
        ++seen;
        const SceneNearFar planes = sceneNearFar(scene, spec);
        INFO("camera " << i);
        REQUIRE(planes.far == Approx(hi * 1.01).epsilon(1e-9));
        REQUIRE(planes.near == Approx(std::max(lo * 0.99, planes.far * 1e-7)).epsilon(1e-9));
    }
    REQUIRE(seen > 30);
}
