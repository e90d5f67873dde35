// Depth maps as real renderers write them: multi-layer EXRs (the depth pass beside the colour),
// "no surface" marked by 0, 65535, 1e10, NaN or +inf, integer maps with a scale and an offset,
// and 8-bit pictures that are not depth maps at all.
#include "zcheck/depth_map_reading.h"
#include "zcheck/error.h"
#include "zcheck/image_io.h"

#include <OpenImageIO/imageio.h>
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <unistd.h>

using namespace zcheck;
namespace fs = std::filesystem;

namespace {

constexpr int W = 3, H = 2;

std::string scratchPath(const std::string& name)
{
    const fs::path dir = fs::temp_directory_path() / ("zcheck_depth_map_test_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    return (dir / name).string();
}

// An EXR whose channel k holds values[k] (W·H each), written as zcheck writes EXRs.
std::string exrWith(const std::string& name, const std::vector<std::string>& channels,
                    const std::vector<std::vector<float>>& values)
{
    std::vector<float> interleaved;
    for (int i = 0; i < W * H; ++i)
        for (const auto& channel : values) interleaved.push_back(channel[std::size_t(i)]);
    const std::string path = scratchPath(name);
    writeExr(path, W, H, channels, interleaved);
    return path;
}

// A one-channel integer TIFF of `type` (UINT8 or UINT16) holding `codes`.
std::string tiffWith(const std::string& name, OIIO::TypeDesc type, const std::vector<unsigned>& codes)
{
    const std::string path = scratchPath(name);
    auto out = OIIO::ImageOutput::create(path);
    REQUIRE(out);
    OIIO::ImageSpec spec(W, H, 1, type);
    REQUIRE(out->open(path, spec));
    std::vector<std::uint16_t> wide(codes.begin(), codes.end());
    std::vector<std::uint8_t> narrow(codes.begin(), codes.end());
    REQUIRE(out->write_image(type, type == OIIO::TypeDesc::UINT8 ? static_cast<const void*>(narrow.data()) : wide.data()));
    REQUIRE(out->close());
    return path;
}

DepthMapFile read(const std::string& path, const DepthMapReading& reading = {}) { return readDepthMap(path, reading, W, H); }

DepthMapReading channelNamed(const std::string& channel)
{
    DepthMapReading r;
    r.channel = channel;
    return r;
}

DepthMapReading declaredChannel(const std::string& quantityChannel)  // zcheck's name for the declared quantity
{
    DepthMapReading r;
    r.quantityChannel = quantityChannel;
    return r;
}

bool same(double read, double expected) { return (std::isnan(read) && std::isnan(expected)) || read == expected; }

void requireValues(const DepthMapFile& map, const std::vector<double>& expected)
{
    REQUIRE(map.value.size() == expected.size());
    for (std::size_t i = 0; i < expected.size(); ++i) {
        INFO("pixel " << i << ": read " << map.value[i] << ", expected " << expected[i]);
        REQUIRE(same(map.value[i], expected[i]));
    }
}

const std::vector<float> kColour = {0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f};
const std::vector<float> kDepth = {1.5f, 2.5f, 3.5f, 4.5f, 5.5f, 6.5f};

}  // namespace

TEST_CASE("regression: a multi-layer EXR was read from its first channel, the colour, not its depth pass", "[depthmap][regression]")
{
    // As Blender writes a render's passes: layer.pass.channel, the colour first.
    const std::string path = exrWith("blender.exr",
                                     {"ViewLayer.Combined.R", "ViewLayer.Combined.G", "ViewLayer.Combined.B",
                                      "ViewLayer.Combined.A", "ViewLayer.Depth.Z"},
                                     {kColour, kColour, kColour, kColour, kDepth});
    const DepthMapFile map = read(path);
    REQUIRE(map.channel == "ViewLayer.Depth.Z");
    requireValues(map, {1.5, 2.5, 3.5, 4.5, 5.5, 6.5});
    // The declared quantity's own channel name does not mislead the choice when it is absent.
    REQUIRE(read(path, declaredChannel("window")).channel == "ViewLayer.Depth.Z");
    // --channel reads exactly the one named.
    const DepthMapFile colour = read(path, channelNamed("ViewLayer.Combined.G"));
    REQUIRE(colour.channel == "ViewLayer.Combined.G");
    requireValues(colour, {0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f});
}

TEST_CASE("channels: the only one, the quantity's own, one named as depth; else refused with the list", "[depthmap]")
{
    REQUIRE(read(exrWith("one.exr", {"Y"}, {kDepth})).channel == "Y");
    // zcheck's own export of several quantities: the declared quantity's channel.
    const std::string zcheckExport = exrWith("ours.exr", {"window", "Z", "distance"}, {kColour, kDepth, kDepth});
    REQUIRE(read(zcheckExport, declaredChannel("Z")).channel == "Z");
    REQUIRE(read(zcheckExport, declaredChannel("window")).channel == "window");
    // Names as other tools write them.
    REQUIRE(read(exrWith("depth.exr", {"R", "G", "B", "depth"}, {kColour, kColour, kColour, kDepth})).channel == "depth");
    REQUIRE(read(exrWith("layer.exr", {"rgba.R", "pass.Depth"}, {kColour, kDepth})).channel == "pass.Depth");

    const std::string rgb = exrWith("rgb.exr", {"R", "G", "B"}, {kColour, kColour, kColour});
    REQUIRE_THROWS_WITH(read(rgb), Catch::Contains("rgb.exr") && Catch::Contains("none of its 3 channels ('R', 'G', 'B')") &&
                                       Catch::Contains("--channel"));
    const std::string two = exrWith("two.exr", {"a.Z", "b.depth", "c.R"}, {kDepth, kDepth, kColour});
    REQUIRE_THROWS_WITH(read(two), Catch::Contains("several of its channels are named as depth ('a.Z', 'b.depth')") &&
                                       Catch::Contains("--channel"));
    REQUIRE_THROWS_WITH(read(rgb, channelNamed("Depth.Z")), Catch::Contains("it has no channel 'Depth.Z'; its channels are 'R', 'G', 'B'"));
}

TEST_CASE("a 3-channel PFM is refused without --channel and read from the channel named", "[depthmap]")
{
    const std::string path = scratchPath("rgb.pfm");
    {
        std::ofstream out(path, std::ios::binary);
        out << "PF\n" << W << " " << H << "\n-1.0\n";
        for (int i = 0; i < W * H; ++i) {
            const float rgb[3] = {0.0f, float(i), 0.5f};
            out.write(reinterpret_cast<const char*>(rgb), sizeof rgb);
        }
    }
    REQUIRE_THROWS_WITH(read(path), Catch::Contains("none of its 3 channels ('R', 'G', 'B')"));
    // PFM rows run bottom to top: the file's first row (0, 1, 2) is the picture's last.
    requireValues(read(path, channelNamed("G")), {3, 4, 5, 0, 1, 2});
}

TEST_CASE("miss values: a number, nan, inf or a comparison, matched on the stored value before scale", "[depthmap]")
{
    const float inf = INFINITY, nan = NAN;
    const std::string path = exrWith("misses.exr", {"Z"}, {{0.0f, 2.0f, 1e10f, inf, nan, 65535.0f}});
    auto withMiss = [&](const std::string& rule, double scale = 0) {
        DepthMapReading r;
        r.miss = MissRule::parse(rule);
        r.scale = scale;
        return read(path, r);
    };
    requireValues(read(path), {0.0, 2.0, 1e10, INFINITY, NAN, 65535.0});  // only NaN is a miss by default
    requireValues(withMiss(">=1e9"), {0.0, 2.0, NAN, NAN, NAN, 65535.0});
    requireValues(withMiss(" > 1e9 "), {0.0, 2.0, NAN, NAN, NAN, 65535.0});
    requireValues(withMiss("0"), {NAN, 2.0, 1e10, INFINITY, NAN, 65535.0});
    requireValues(withMiss("inf"), {0.0, 2.0, 1e10, NAN, NAN, 65535.0});
    requireValues(withMiss("+inf"), {0.0, 2.0, 1e10, NAN, NAN, 65535.0});
    requireValues(withMiss("nan"), {0.0, 2.0, 1e10, INFINITY, NAN, 65535.0});
    requireValues(withMiss("<=0"), {NAN, 2.0, 1e10, INFINITY, NAN, 65535.0});
    // Compared before scale: 65535 stored is the miss, whatever the scale.
    requireValues(withMiss("65535", 1000), {0.0, 0.002, 1e7, INFINITY, NAN, NAN});
    for (const std::string bad : {"", "abc", ">=", ">=inf", "<nan", "1e10x", "==3"})
        REQUIRE_THROWS_WITH(MissRule::parse(bad), Catch::Contains("miss value '" + bad + "' is neither a number"));
    REQUIRE(MissRule::parse(">=1e9").text() == ">=1e9");
}

TEST_CASE("integer maps: depth = stored / scale + offset, 0 a miss unless --miss says otherwise; 8 bits refused", "[depthmap]")
{
    const std::string path = tiffWith("mm.tif", OIIO::TypeDesc::UINT16, {0, 1000, 1500, 5000, 65534, 65535});
    DepthMapReading millimetres;
    millimetres.scale = 1000;
    DepthMapFile map = read(path, millimetres);
    requireValues(map, {NAN, 1.0, 1.5, 5.0, 65.534, 65.535});
    REQUIRE(map.valueQuantum == 1.0 / 1000);
    DepthMapReading shifted = millimetres;
    shifted.offset = 0.25;
    requireValues(read(path, shifted), {NAN, 1.25, 1.75, 5.25, 65.534 + 0.25, 65.535 + 0.25});
    DepthMapReading saturated = millimetres;  // a depth buffer dump: 0 is the near plane, 65535 the clear value
    saturated.miss = MissRule::parse("65535");
    requireValues(read(path, saturated), {0.0, 1.0, 1.5, 5.0, 65.534, NAN});
    REQUIRE_THROWS_WITH(read(path), Catch::Contains("stores integers") && Catch::Contains("give --scale"));

    const std::string picture = tiffWith("picture.tif", OIIO::TypeDesc::UINT8, {0, 10, 20, 30, 40, 255});
    REQUIRE_THROWS_WITH(read(picture, millimetres),
                        Catch::Contains("picture.tif") && Catch::Contains("8-bit integers, which cannot hold depth"));
    DepthMapReading badOffset;
    badOffset.offset = INFINITY;
    REQUIRE_THROWS_WITH(read(path, badOffset), Catch::Contains("--offset must be a finite number"));
}
