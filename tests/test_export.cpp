// Export: every quantity through every format and back through OpenImageIO.
#include "zcheck/checker.h"

#include "zcheck/atomic_file.h"
#include "zcheck/error.h"
#include "zcheck/export.h"
#include "zcheck/image_io.h"
#include "zcheck/inverse_projection.h"

#include <OpenImageIO/imageio.h>
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <unistd.h>

using namespace zcheck;
namespace fs = std::filesystem;

namespace {

fs::path scratch()
{
    const fs::path dir = fs::temp_directory_path() / ("zcheck_export_test_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    return dir;
}

// One channel of a file as floats (or, for uint channels, the raw uint32 values), row 0 first.
std::vector<double> readChannel(const std::string& path, const std::string& channel, bool asUnsigned = false)
{
    auto in = OIIO::ImageInput::open(path);
    REQUIRE(in);
    const OIIO::ImageSpec& spec = in->spec();
    const int c = spec.channelnames.size() == 1 ? 0 : spec.channelindex(channel);
    INFO(path << " channel " << channel);
    REQUIRE(c >= 0);
    std::vector<double> out(std::size_t(spec.width) * spec.height);
    if (asUnsigned) {
        std::vector<std::uint32_t> raw(out.size());
        REQUIRE(in->read_image(0, 0, c, c + 1, OIIO::TypeDesc::UINT32, raw.data()));
        for (std::size_t i = 0; i < raw.size(); ++i) out[i] = raw[i];
    } else if (spec.format == OIIO::TypeDesc::UINT16) {
        std::vector<std::uint16_t> raw(out.size());
        REQUIRE(in->read_image(0, 0, c, c + 1, OIIO::TypeDesc::UINT16, raw.data()));
        for (std::size_t i = 0; i < raw.size(); ++i) out[i] = raw[i];
    } else {
        std::vector<float> raw(out.size());
        REQUIRE(in->read_image(0, 0, c, c + 1, OIIO::TypeDesc::FLOAT, raw.data()));
        for (std::size_t i = 0; i < raw.size(); ++i) out[i] = raw[i];
    }
    return out;
}

// Exact equality of binary32 values, with NaN equal to NaN.
bool sameFloat(double read, double expected)
{
    const float e = float(expected);
    return (std::isnan(read) && std::isnan(e)) || float(read) == e;
}

struct Fixture {
    Scene scene = builtinScene("builtin:default");
    CameraSpec spec;
    Fixture()
    {
        spec = scene.defaultCamera;
        spec.width = 96, spec.height = 72;  // small and not square
    }
};

}  // namespace

TEST_CASE("every quantity round-trips through every format that holds it", "[export]")
{
    Fixture f;
    const fs::path dir = scratch();
    for (bool reversed : {false, true}) {
        CameraSpec spec = f.spec;
        spec.depth.reversed = reversed;
        const Camera camera(spec);
        const CheckResult run = Checker(f.scene).check(camera);
        for (const RenderResult* route : {&run.ray, &run.raster}) {
            std::vector<QuantityImage> all;
            for (const auto& name : exportQuantityNames())
                all.push_back(quantityImage(f.scene, camera, *route, exportQuantitiesFromList(name).front()));
            // Everything into one EXR.
            const std::string exr = (dir / "all.exr").string();
            writeQuantityFile(exr, all, 0);
            for (const QuantityImage& q : all) {
                const std::size_t C = q.channels.size();
                for (std::size_t c = 0; c < C; ++c) {
                    const std::vector<double> read = readChannel(exr, q.channels[c], q.quantity == ExportQuantity::PrimitiveId);
                    for (std::size_t i = 0; i < read.size(); ++i) {
                        INFO("exr " << q.channels[c] << " pixel " << i);
                        if (q.quantity == ExportQuantity::PrimitiveId)
                            REQUIRE(read[i] == double(q.id[i]));
                        else
                            REQUIRE(sameFloat(read[i], q.value[i * C + c]));
                    }
                }
                // Each single quantity alone into PFM (1 or 3 channels) and TIFF.
                for (const std::string ext : {".pfm", ".tif"}) {
                    if (ext == ".pfm" && q.quantity == ExportQuantity::PrimitiveId) {
                        REQUIRE_THROWS_WITH(writeQuantityFile((dir / ("x" + ext)).string(), {q}, 0), Catch::Contains("PFM"));
                        continue;
                    }
                    const std::string path = (dir / ("one" + ext)).string();
                    writeQuantityFile(path, {q}, 0);
                    for (std::size_t c = 0; c < C; ++c) {
                        auto in = OIIO::ImageInput::open(path);
                        REQUIRE(in);
                        std::vector<double> read(std::size_t(camera.width()) * camera.height());
                        if (q.quantity == ExportQuantity::PrimitiveId) {
                            // Integers are read raw: OpenImageIO would scale them to [0,1] as floats.
                            std::vector<std::uint32_t> raw(read.size());
                            REQUIRE(in->read_image(0, 0, 0, 1, OIIO::TypeDesc::UINT32, raw.data()));
                            std::copy(raw.begin(), raw.end(), read.begin());
                        } else {
                            REQUIRE(in->read_image(0, 0, int(c), int(c) + 1, OIIO::TypeDesc::DOUBLE, read.data()));
                        }
                        for (std::size_t i = 0; i < read.size(); ++i) {
                            INFO(ext << " " << toString(q.quantity) << " channel " << c << " pixel " << i);
                            if (q.quantity == ExportQuantity::PrimitiveId)
                                REQUIRE(std::uint32_t(read[i]) == q.id[i]);
                            else
                                REQUIRE(sameFloat(read[i], q.value[i * C + c]));
                        }
                    }
                }
            }
            // Depth quantities into 16-bit PNG: within half a quantum, misses 0.
            for (ExportQuantity q : {ExportQuantity::Window, ExportQuantity::EyeZ, ExportQuantity::Distance}) {
                const QuantityImage image = quantityImage(f.scene, camera, *route, q);
                const double scale = q == ExportQuantity::Window ? 65535.0 : 1000.0;
                const std::string path = (dir / "depth.png").string();
                writeQuantityFile(path, {image}, scale);
                const std::vector<double> read = readChannel(path, "");
                for (std::size_t i = 0; i < read.size(); ++i) {
                    INFO("png " << toString(q) << " pixel " << i);
                    if (image.isMiss(i))
                        REQUIRE(read[i] == 0);
                    else
                        REQUIRE(std::abs(read[i] / scale - image.value[i]) <= 0.5 / scale + 1e-12);
                }
            }
        }
    }
    fs::remove_all(dir);
}

TEST_CASE("PFM stores rows bottom to top, and reads back like the EXR", "[export]")
{
    Fixture f;
    const fs::path dir = scratch();
    const Camera camera(f.spec);
    const RenderResult ray = RayRenderer(f.scene).render(camera);
    const QuantityImage eyeZ = quantityImage(f.scene, camera, ray, ExportQuantity::EyeZ);
    const std::string pfm = (dir / "d.pfm").string(), exr = (dir / "d.exr").string();
    writeQuantityFile(pfm, {eyeZ}, 0);
    writeQuantityFile(exr, {eyeZ}, 0);
    const std::vector<double> fromPfm = readChannel(pfm, "Z"), fromExr = readChannel(exr, "Z");
    for (std::size_t i = 0; i < fromPfm.size(); ++i) REQUIRE(sameFloat(fromPfm[i], fromExr[i]));
    // By hand: after the 3-line header, the first stored row is the picture's bottom row.
    std::ifstream in(pfm, std::ios::binary);
    std::string magic, size, scale;
    std::getline(in, magic), std::getline(in, size), std::getline(in, scale);
    REQUIRE(magic == "Pf");
    REQUIRE(size == "96 72");
    REQUIRE(std::stod(scale) < 0);  // little-endian
    std::vector<float> firstStored(96);
    in.read(reinterpret_cast<char*>(firstStored.data()), 96 * sizeof(float));
    const std::size_t bottom = std::size_t(71) * 96;
    for (std::size_t x = 0; x < 96; ++x) REQUIRE(sameFloat(firstStored[x], eyeZ.value[bottom + x]));
    fs::remove_all(dir);
}

TEST_CASE("16-bit PNG refuses values it cannot hold, naming the largest depth and scale", "[export]")
{
    Fixture f;
    const Camera camera(f.spec);
    const RenderResult ray = RayRenderer(f.scene).render(camera);
    const QuantityImage eyeZ = quantityImage(f.scene, camera, ray, ExportQuantity::EyeZ);
    const std::string path = (scratch() / "overflow.png").string();
    REQUIRE_THROWS_WITH(writeQuantityFile(path, {eyeZ}, 1e5), Catch::Contains("largest eye-z") && Catch::Contains("largest scale that fits"));
    REQUIRE_THROWS_WITH(writeQuantityFile(path, {eyeZ}, 0), Catch::Contains("--scale"));
    REQUIRE_THROWS_WITH(writeQuantityFile(path, {quantityImage(f.scene, camera, ray, ExportQuantity::Normal)}, 1000),
                        Catch::Contains("one depth quantity"));
    REQUIRE_THROWS_WITH(writeQuantityFile(path, {eyeZ, eyeZ}, 1000), Catch::Contains("only as .exr"));
    REQUIRE_FALSE(fs::exists(path));
}

TEST_CASE("an interrupted write leaves the old file intact and no temporary behind", "[export][atomic]")
{
    const fs::path dir = scratch();
    const std::string path = (dir / "depth.exr").string();
    writeTextFileAtomically(path, "the old file");
    REQUIRE_THROWS_WITH(writeAtomically(path,
                                        [](const std::string& temporary) {
                                            std::ofstream(temporary) << "half a new fi";
                                            throw Error("disk full, say");
                                        }),
                        Catch::Contains("disk full"));
    std::ifstream in(path);
    std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    REQUIRE(content == "the old file");
    std::size_t files = 0;
    for (const auto& entry : fs::directory_iterator(dir)) files += entry.is_regular_file() ? 1 : 0;
    REQUIRE(files == 1);
    fs::remove_all(dir);
}

namespace {
std::string contentOf(const fs::path& path)
{
    std::ifstream in(path, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}
std::size_t regularFilesIn(const fs::path& dir)
{
    std::size_t files = 0;
    for (const auto& entry : fs::recursive_directory_iterator(dir)) files += entry.is_regular_file() ? 1 : 0;
    return files;
}
}  // namespace

TEST_CASE("a run's outputs appear all together or not at all", "[export][atomic]")
{
    const fs::path dir = scratch();
    const std::string image = (dir / "depth.exr").string(), sidecar = image + ".json";
    writeTextFileAtomically(image, "old image");
    writeTextFileAtomically(sidecar, "old sidecar");
    {
        // The image is written, then the sidecar fails: neither old file changes.
        OutputFiles outputs;
        outputs.add(image, "-o");
        outputs.add(sidecar, "the sidecar");
        outputs.writeText(image, "new image");
        REQUIRE_THROWS_WITH(outputs.write(sidecar, [](const std::string&) { throw Error("no space left, say"); }),
                            Catch::Contains("no space left"));
    }
    REQUIRE(contentOf(image) == "old image");
    REQUIRE(contentOf(sidecar) == "old sidecar");
    REQUIRE(regularFilesIn(dir) == 2);  // no temporary left
    {
        // A folder that did not exist is made for the run, and removed again when it fails.
        OutputFiles outputs;
        const std::string folder = (dir / "new").string(), report = folder + "/report.json";
        outputs.addFolder(folder, "--out");
        outputs.add(report, "--out");
        outputs.writeText(report, "{}");
    }
    REQUIRE_FALSE(fs::exists(dir / "new"));
    {
        OutputFiles outputs;
        outputs.add(image, "-o");
        outputs.add(sidecar, "the sidecar");
        outputs.writeText(image, "new image");
        outputs.writeText(sidecar, "new sidecar");
        REQUIRE(contentOf(image) == "old image");  // nothing moves before commit
        outputs.commit();
    }
    REQUIRE(contentOf(image) == "new image");
    REQUIRE(contentOf(sidecar) == "new sidecar");
    REQUIRE(regularFilesIn(dir) == 2);
    fs::remove_all(dir);
}

TEST_CASE("outputs are refused before the run: an input, a duplicate, a folder, a missing folder", "[export][atomic]")
{
    const fs::path dir = scratch();
    const std::string input = (dir / "map.pfm").string();
    writeTextFileAtomically(input, "input");
    fs::create_directories(dir / "sub");
    OutputFiles outputs;
    outputs.addInput(input);
    REQUIRE_THROWS_WITH(outputs.add(input, "-o"), Catch::Contains("it is an input of this run"));
    // The same file through another spelling, and through a symbolic link.
    REQUIRE_THROWS_WITH(outputs.add((dir / "sub" / ".." / "map.pfm").string(), "-o"), Catch::Contains("input of this run"));
    fs::create_symlink(input, dir / "link.pfm");
    REQUIRE_THROWS_WITH(outputs.add((dir / "link.pfm").string(), "-o"), Catch::Contains("input of this run"));
    outputs.add((dir / "a.png").string(), "-o");
    REQUIRE_THROWS_WITH(outputs.add((dir / "a.png").string(), "--preview"), Catch::Contains("-o writes the same file"));
    REQUIRE_THROWS_WITH(outputs.add((dir / "sub").string(), "-o"), Catch::Contains("it is a folder"));
    REQUIRE_THROWS_WITH(outputs.add((dir / "missing" / "x.png").string(), "-o"), Catch::Contains("does not exist"));
    REQUIRE_THROWS_WITH(outputs.add("", "-o"), Catch::Contains("-o: the output path is empty"));
    fs::remove_all(dir);
}

TEST_CASE("exports of the ray and raster routes agree within the tolerance model", "[export]")
{
    Fixture f;
    const fs::path dir = scratch();
    for (const auto& convention : Convention::presetNames())
        for (DepthFormat format : {DepthFormat::Float32, DepthFormat::Unorm24, DepthFormat::Unorm16}) {
            CameraSpec spec = f.spec;
            spec.convention = Convention::preset(convention);
            spec.depth.format = format;
            const Camera camera(spec);
            const CheckResult run = Checker(f.scene).check(camera);
            // Export window depth and ids from both routes, read the files back, compare them.
            RenderResult fromFile[2];
            for (int r = 0; r < 2; ++r) {
                const RenderResult& route = r == 0 ? run.ray : run.raster;
                const std::string path = (dir / "route.exr").string();
                writeQuantityFile(path,
                                  {quantityImage(f.scene, camera, route, ExportQuantity::Window),
                                   quantityImage(f.scene, camera, route, ExportQuantity::PrimitiveId)},
                                  0);
                const std::vector<double> window = readChannel(path, "window"), id = readChannel(path, "id", true);
                fromFile[r].windowDepth = {camera.width(), camera.height(), DepthQuantity::Window, {window.begin(), window.end()}};
                for (double v : id) fromFile[r].primitiveId.push_back(std::uint32_t(v));
            }
            const ComparisonReport report = compareRoutes(f.scene, camera, fromFile[0], fromFile[1]).report;
            INFO(convention << " " << toString(format) << ": depth errors " << report.depthErrors << ", unexplained coverage "
                            << report.coverageUnexplained << ", max/tol " << report.maxErrorOverTolerance);
            REQUIRE(report.bothHit > 1000);
            REQUIRE(report.consistent());
        }
    fs::remove_all(dir);
}

TEST_CASE("unknown or repeated quantities are refused", "[export]")
{
    REQUIRE_THROWS_WITH(exportQuantitiesFromList("eye-z,depth"), Catch::Contains("unknown quantity 'depth'"));
    REQUIRE_THROWS_WITH(exportQuantitiesFromList("eye-z,eye-z"), Catch::Contains("twice"));
    REQUIRE(exportQuantitiesFromList("normal,primitive-id").size() == 2);
}
