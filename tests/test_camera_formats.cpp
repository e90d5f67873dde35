// The table of camera formats (camera_formats.h): names and aliases, the lists help prints,
// and detection by content against every format's seeds (the fuzz corpora, the examples, the
// gltf corpus): each seed is told as its own format, and a format that would also claim it comes
// later in the detection order.
#include "zcheck/camera_formats.h"
#include "zcheck/camera_import.h"
#include "zcheck/camera_sources.h"
#include "zcheck/error.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <unistd.h>

using namespace zcheck;
namespace fs = std::filesystem;

namespace {

const fs::path kSource = fs::path(ZCHECK_TESTS_DIR).parent_path();

std::string bytesOf(const fs::path& path)
{
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), {}};
}

fs::path scratch(const std::string& name)
{
    const fs::path dir = fs::temp_directory_path() / ("zcheck_formats_" + std::to_string(::getpid())) / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

struct Seed {
    fs::path path;       // a file or a COLMAP model folder
    std::string format;  // the format it is
};

// The fuzz harness's inputs (fuzz_camera_import.cpp) name their format on the first line; a
// COLMAP model's two files are separated by "\n--8<--\n". Made into the files they stand for.
std::vector<Seed> seeds()
{
    std::vector<Seed> out;
    const fs::path dir = scratch("seeds");
    for (const auto& entry : fs::directory_iterator(kSource / "fuzz" / "corpus" / "camera_import")) {
        const std::string input = bytesOf(entry.path());
        const std::string name = input.substr(0, input.find('\n')), body = input.substr(input.find('\n') + 1);
        const fs::path file = dir / entry.path().filename();
        if (name == "manifest") continue;
        if (name == "colmap-text" || name == "colmap-bin") {
            const std::string suffix = name == "colmap-bin" ? ".bin" : ".txt";
            const std::size_t cut = body.find("\n--8<--\n");
            fs::create_directories(file);
            std::ofstream(file / ("cameras" + suffix), std::ios::binary) << body.substr(0, cut);
            std::ofstream(file / ("images" + suffix), std::ios::binary) << (cut == std::string::npos ? "" : body.substr(cut + 8));
            out.push_back({file, "colmap"});
            continue;
        }
        std::ofstream(file, std::ios::binary) << body;
        out.push_back({file, name});
    }
    for (const fs::path& folder : {kSource / "fuzz" / "corpus" / "camera", kSource / "examples"})
        for (const auto& entry : fs::directory_iterator(folder))
            if (entry.path().extension() == ".json") out.push_back({entry.path(), "zcheck"});
    for (const auto& entry : fs::directory_iterator(kSource / "fuzz" / "corpus" / "gltf")) out.push_back({entry.path(), "gltf"});
    return out;
}

}  // namespace

TEST_CASE("camera formats: every name and alias names its row, and an unknown one is refused listing them all")
{
    (void)gltfCameraFormat();
    std::vector<std::string> names;
    for (const CameraFormat* format : cameraFormats()) {
        REQUIRE(&cameraFormatNamed(format->name) == format);
        for (const std::string& alias : format->aliases) REQUIRE(&cameraFormatNamed(alias) == format);
        REQUIRE(format->detects);
        REQUIRE((format->parse != nullptr) != (format->read != nullptr));  // one reader or the other
        REQUIRE(!format->title.empty());
        REQUIRE(!format->example.empty());
        REQUIRE(!format->extensions.empty());
        names.push_back(format->name);
    }
    // glTF is the scene library's row, registered because this program links zcheck::scene.
    REQUIRE(std::count(names.begin(), names.end(), "gltf") == 1);
    for (const std::string& name : names) REQUIRE(std::count(names.begin(), names.end(), name) == 1);
    try {
        (void)cameraFormatNamed("bundler");
        FAIL("an unknown format was accepted");
    } catch (const Error& e) {
        const std::string what = e.what();
        REQUIRE_THAT(what, Catch::Contains("unknown camera format 'bundler'"));
        for (const std::string& name : names) REQUIRE_THAT(what, Catch::Contains(name));
    }
    REQUIRE_THROWS_WITH(registerCameraFormat(cameraFormatNamed("colmap")), Catch::Contains("registered twice"));
}

TEST_CASE("camera formats: each seed is detected as its format, any other format claiming it comes later")
{
    const std::vector<Seed> all = seeds();
    REQUIRE(all.size() > 30);
    std::vector<std::string> covered;
    for (const Seed& seed : all) {
        INFO(seed.path.string() << " (" << seed.format << ")");
        REQUIRE(detectCameraFormat(seed.path.string()).name == seed.format);
        const CameraFormat& own = cameraFormatNamed(seed.format);
        const std::string head = fs::is_directory(seed.path) ? "" : bytesOf(seed.path).substr(0, 1 << 20);
        std::string_view view = head;
        while (!view.empty() && std::isspace(static_cast<unsigned char>(view.front()))) view.remove_prefix(1);
        const CameraFileHead file{seed.path.string(), view, fs::is_directory(seed.path)};
        REQUIRE(own.detects(file));
        for (const CameraFormat* other : cameraFormats())
            if (other != &own && other->detects(file)) {
                INFO("also claimed by " << other->name);
                REQUIRE(other->priority > own.priority);
            }
        covered.push_back(seed.format);
    }
    for (const CameraFormat* format : cameraFormats()) {
        INFO(format->name << " has no seed: add its examples to seeds()");
        REQUIRE(std::count(covered.begin(), covered.end(), format->name) > 0);
    }
}

TEST_CASE("camera formats: the lists help prints come from the table")
{
    const std::string readers = cameraFormatChoices(CameraFormatsWith::Reader);
    const std::string writers = cameraFormatChoices(CameraFormatsWith::Writer);
    const std::string datasets = cameraFormatChoices(CameraFormatsWith::Dataset);
    const std::string table = cameraFormatTable();
    for (const CameraFormat* format : cameraFormats()) {
        INFO(format->name);
        REQUIRE_THAT(readers, Catch::Contains(format->name));
        REQUIRE_THAT(table, Catch::Contains("| `" + format->name + "`"));
        REQUIRE((writers.find(format->name) != std::string::npos) == (format->write != nullptr));
        REQUIRE((datasets.find(format->name) != std::string::npos) == format->datasetSource);
    }
    REQUIRE_THAT(readers, Catch::Contains("nerfstudio (instant-ngp)"));
    REQUIRE_THROWS_WITH(cameraInFormat(Camera(CameraSpec{}), cameraFormatNamed("ros"), "x"),
                        Catch::Contains("cameras are written as") && Catch::Contains("not ros"));
}

TEST_CASE("camera formats: docs/camera.md describes what each format's reader reads, one row per format")
{
    (void)gltfCameraFormat();
    std::istringstream docs(bytesOf(kSource / "docs" / "camera.md"));
    std::vector<std::string> described;
    bool inTable = false;
    for (std::string line; std::getline(docs, line);) {
        if (line.rfind("| format | what is read |", 0) == 0) inTable = true;
        else if (inTable && line.rfind("| `", 0) == 0) described.push_back(line.substr(3, line.find('`', 3) - 3));
        else if (inTable && line.rfind("|---", 0) != 0) inTable = false;
    }
    std::vector<std::string> names;
    for (const CameraFormat* format : cameraFormats()) names.push_back(format->name);
    std::sort(described.begin(), described.end());
    std::sort(names.begin(), names.end());
    REQUIRE(described == names);
}
