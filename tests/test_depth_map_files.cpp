// Depth maps as real renderers write them: multi-layer EXRs (the depth pass beside the colour),
// "no surface" marked by 0, 65535, 1e10, NaN or +inf, integer maps with a scale and an offset,
// and 8-bit pictures that are not depth maps at all.
#include "zcheck/depth_map_formats.h"
#include "zcheck/depth_map_reading.h"
#include "zcheck/error.h"
#include "zcheck/image_io.h"

#include <OpenImageIO/imageio.h>
#include <catch2/catch.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <thread>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <unistd.h>
#include <vector>

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

TEST_CASE("channels: the only one, the quantity's own, one named as depth, else refused with the list", "[depthmap]")
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

TEST_CASE("depthsFromStored: the one rule readers and Python's arrays apply to stored values", "[depthmap]")
{
    DepthMapReading millimetres;
    millimetres.scale = 1000, millimetres.offset = 0.5;
    DepthMapFile integers;
    integers.width = 3, integers.height = 1, integers.value = {0, 1500, 65535};
    depthsFromStored(integers, StoredValues::Integer, millimetres);
    REQUIRE(std::isnan(integers.value[0]));  // 0 is a miss in integer maps
    REQUIRE(integers.value[1] == Approx(2.0));
    REQUIRE(integers.value[2] == Approx(66.035));
    REQUIRE(integers.valueQuantum == Approx(0.001));
    REQUIRE(integers.valueStep.empty());

    DepthMapFile halves;
    halves.width = 2, halves.height = 1, halves.value = {1.0, 1000.0};
    depthsFromStored(halves, StoredValues::Half, DepthMapReading{});
    REQUIRE(halves.value == std::vector<double>{1.0, 1000.0});
    REQUIRE(halves.valueStep == std::vector<float>{float(std::ldexp(1.0, -10)), 0.5f});  // binary16's spacing
    REQUIRE(halves.valueQuantum == 0);

    DepthMapFile floats;
    floats.width = 3, floats.height = 1, floats.value = {0.0, NAN, 2.0};
    depthsFromStored(floats, StoredValues::Float, DepthMapReading{});
    REQUIRE(floats.value[0] == 0.0);  // a float 0 is a value (the quantity decides whether it is a miss)
    REQUIRE(std::isnan(floats.value[1]));
    REQUIRE(floats.value[2] == 2.0);
    REQUIRE((floats.valueStep.empty() && floats.valueQuantum == 0));

    REQUIRE_THROWS_WITH(DepthMapReading::requireScale(-2, "scale"), "scale must be a positive finite number, got -2");
    REQUIRE_THROWS_WITH(DepthMapReading::requireOffset(INFINITY, "--offset"), "--offset must be a finite number, got inf");
    REQUIRE(MapAccuracy::requireDeclared(0.5, "rel_tolerance", true) == 0.5);
    REQUIRE_THROWS_WITH(MapAccuracy::requireDeclared(1, "rel_tolerance", true),
                        "rel_tolerance must be a finite number >= 0 and below 1, got 1");
    REQUIRE_THROWS_WITH(MapAccuracy::requireDeclared(-0.1, "quantum", false), "quantum must be a finite number >= 0, got -0.1");
}

TEST_CASE("integer maps: depth = stored / scale + offset, 0 a miss unless --miss says otherwise, 8 bits refused", "[depthmap]")
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

namespace {

std::string bytesFile(const std::string& name, const std::string& bytes)
{
    const std::string path = scratchPath(name);
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
}

// A .npy file built by hand from the format's definition (numpy.org, NEP 1): the magic, the
// version, the header length, the header dict padded to 64 bytes, then the data.
std::string npy(const std::string& dict, const std::string& data, int major = 1)
{
    std::string header = dict;
    const std::size_t lengthBytes = major == 1 ? 2 : 4;
    while ((8 + lengthBytes + header.size() + 1) % 64 != 0) header += ' ';
    header += '\n';
    std::string out("\x93NUMPY", 6);
    out += char(major), out += char(0);
    for (std::size_t k = 0; k < lengthBytes; ++k) out += char((header.size() >> (8 * k)) & 0xFF);
    return out + header + data;
}

template <class T>
std::string raw(const std::vector<T>& values, bool bigEndian = false)
{
    std::string out;
    for (T v : values) {
        char b[sizeof(T)];
        std::memcpy(b, &v, sizeof(T));
        if (bigEndian) std::reverse(b, b + sizeof(T));
        out.append(b, sizeof(T));
    }
    return out;
}

}  // namespace

TEST_CASE("NumPy .npy maps: float32, big-endian float64, float16, Fortran order, uint16 with a scale, channels", "[depthmap][npy]")
{
    // Row 0 = {1, 2, 3}, row 1 = {4, 5, 6}: a 3x2 map.
    const std::vector<float> rows = {1, 2, 3, 4, 5, 6};
    auto values = [](const DepthMapFile& m) { return m.value; };
    const std::vector<double> expected = {1, 2, 3, 4, 5, 6};
    REQUIRE(values(read(bytesFile("f4.npy", npy("{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3), }", raw(rows))))) == expected);
    REQUIRE(values(read(bytesFile("f8be.npy", npy("{'descr': '>f8', 'fortran_order': False, 'shape': (2, 3), }",
                                                   raw(std::vector<double>(rows.begin(), rows.end()), true), 2)))) == expected);
    // Fortran order stores column by column: 1, 4, 2, 5, 3, 6.
    REQUIRE(values(read(bytesFile("fortran.npy", npy("{'descr': '<f4', 'fortran_order': True, 'shape': (2, 3), }",
                                                      raw(std::vector<float>{1, 4, 2, 5, 3, 6}))))) == expected);
    // float16: 1.0 = 0x3C00, 2.0 = 0x4000, 0.5 = 0x3800, 1.5 = 0x3E00, 65504 = 0x7BFF, NaN = 0x7E00.
    const DepthMapFile half = read(bytesFile("f2.npy", npy("{'descr': '<f2', 'fortran_order': False, 'shape': (2, 3), }",
                                                          raw(std::vector<std::uint16_t>{0x3C00, 0x4000, 0x3800, 0x3E00, 0x7BFF, 0x7E00}))));
    REQUIRE(half.value[0] == 1.0);
    REQUIRE(half.value[2] == 0.5);
    REQUIRE(half.value[4] == 65504.0);
    REQUIRE(std::isnan(half.value[5]));
    // uint16 millimetres: a scale is required, 0 is a miss.
    const std::string mm = bytesFile("u2.npy", npy("{'descr': '<u2', 'fortran_order': False, 'shape': (2, 3), }",
                                                   raw(std::vector<std::uint16_t>{1000, 0, 2500, 1, 2, 3})));
    REQUIRE_THROWS_WITH(read(mm), Catch::Contains("stores integers (.npy <u2): give --scale"));
    DepthMapReading millimetres;
    millimetres.scale = 1000;
    const DepthMapFile metres = read(mm, millimetres);
    REQUIRE(metres.value[0] == 1.0);
    REQUIRE(std::isnan(metres.value[1]));
    REQUIRE(metres.valueQuantum == 0.001);
    // (H, W, C): channels are named by index; several need --channel.
    std::vector<float> three;
    for (float v : rows) three.insert(three.end(), {v, 10 * v, 100 * v});
    const std::string rgb = bytesFile("hwc.npy", npy("{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3, 3), }", raw(three)));
    REQUIRE_THROWS_WITH(read(rgb), Catch::Contains("name the one to read with --channel"));
    REQUIRE(read(rgb, channelNamed("1")).value[5] == 60.0);
}

TEST_CASE("NumPy .npy maps that are not depth maps are refused by name", "[depthmap][npy][validation]")
{
    const std::string six = raw(std::vector<float>{1, 2, 3, 4, 5, 6});
    auto refuses = [&](const std::string& name, const std::string& bytes, const std::string& what) {
        INFO(name);
        REQUIRE_THROWS_WITH(read(bytesFile(name, bytes)), Catch::Contains(what));
    };
    refuses("u1.npy", npy("{'descr': '|u1', 'fortran_order': False, 'shape': (2, 3), }", "123456"), "8-bit integers");
    refuses("bool.npy", npy("{'descr': '|b1', 'fortran_order': False, 'shape': (2, 3), }", "123456"), "is not one zcheck reads");
    refuses("i8.npy", npy("{'descr': '<i8', 'fortran_order': False, 'shape': (2, 3), }", six + six), "is not one zcheck reads");
    refuses("c8.npy", npy("{'descr': '<c8', 'fortran_order': False, 'shape': (2, 3), }", six + six), "is not one zcheck reads");
    refuses("struct.npy", npy("{'descr': [('a', '<f4')], 'fortran_order': False, 'shape': (2, 3), }", six), "structured");
    refuses("1d.npy", npy("{'descr': '<f4', 'fortran_order': False, 'shape': (6,), }", six), "1 dimensions");
    refuses("short.npy", npy("{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3), }", six.substr(0, 20)), "(truncated)");
    refuses("size.npy", npy("{'descr': '<f4', 'fortran_order': False, 'shape': (3, 3), }", six), "but the camera's image is 3x2");
    refuses("huge.npy", npy("{'descr': '<f4', 'fortran_order': False, 'shape': (99999999999, 3), }", six), "but the camera's image");
    refuses("dict.npy", npy("{'descr': '<f4', 'shape': (2, 3), }", six), "lacks one of");
    refuses("v9.npy", npy("{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3), }", six, 9), "version 9");
    refuses("header.npy", std::string("\x93NUMPY\x01\x00\xff\xff{", 11), "more than the file holds");
}

TEST_CASE("COLMAP dense depth maps: W&H&C& then float32 rows, 0 where there is no depth", "[depthmap][colmap]")
{
    const DepthMapFile map = read(bytesFile("d.geometric.bin", "3&2&1&" + raw(std::vector<float>{1, 0, 3, 4, -1, 6})));
    REQUIRE(map.value[0] == 1.0);
    REQUIRE(std::isnan(map.value[1]));  // 0: no depth
    REQUIRE(std::isnan(map.value[4]));  // below 0: no depth either
    REQUIRE(map.value[5] == 6.0);
    REQUIRE_THROWS_WITH(read(bytesFile("n.bin", "3&2&3&" + raw(std::vector<float>(18, 1.0f)))), Catch::Contains("normal map"));
    REQUIRE_THROWS_WITH(read(bytesFile("t.bin", "3&2&1&" + raw(std::vector<float>(5, 1.0f)))), Catch::Contains("(truncated)"));
    REQUIRE_THROWS_WITH(read(bytesFile("w.bin", "4&2&1&" + raw(std::vector<float>(8, 1.0f)))), Catch::Contains("camera's image is 3x2"));
}

TEST_CASE("HDF5 maps: a dataset chosen by --channel or by its name, malformed files are refused, not fatal", "[depthmap][hdf5]")
{
    QuantityImage depth, distance;
    depth.quantity = ExportQuantity::EyeZ, depth.width = W, depth.height = H, depth.channels = {"depth"};
    depth.value = {1, 2, 3, 4, 5, 6};
    distance = depth;
    distance.quantity = ExportQuantity::Distance, distance.channels = {"distance"};
    distance.value = {10, 20, 30, 40, 50, 60};
    const std::string path = scratchPath("blenderproc.h5");
    REQUIRE(writeQuantityFile(path, {depth, distance}, 0) == "hdf5");
    REQUIRE_THROWS_WITH(read(path), Catch::Contains("several of its channels are named as depth ('depth', 'distance')"));
    REQUIRE(read(path, channelNamed("depth")).value[5] == 6.0);
    DepthMapReading asDistance;
    asDistance.quantityChannel = "distance";  // --quantity distance prefers its own name
    REQUIRE(read(path, asDistance).value[0] == 10.0);
    REQUIRE_THROWS_WITH(read(path, channelNamed("colors")), Catch::Contains("it has no channel 'colors'"));

    // The HDF5 signature and then garbage: the library refuses (or dies) in a child process.
    std::string garbage("\x89HDF\r\n\x1a\n", 8);
    for (int i = 0; i < 4000; ++i) garbage += char((i * 7919) % 251);
    REQUIRE_THROWS_WITH(read(bytesFile("garbage.h5", garbage)), Catch::StartsWith("cannot read depth map") && Catch::Contains("HDF5"));
    // Truncated after a good start.
    std::string whole;
    {
        std::ifstream in(path, std::ios::binary);
        whole.assign(std::istreambuf_iterator<char>(in), {});
    }
    REQUIRE_THROWS_WITH(read(bytesFile("cut.h5", whole.substr(0, whole.size() / 2)), channelNamed("depth")),
                        Catch::StartsWith("cannot read depth map"));
}

TEST_CASE("regression: HDF5 maps were read in a bare fork of a multithreaded process", "[depthmap][hdf5]")
{
    // The reader is a program of its own, started with posix_spawn: many threads read at once.
    QuantityImage depth;
    depth.quantity = ExportQuantity::EyeZ, depth.width = W, depth.height = H, depth.channels = {"depth"};
    depth.value = {1, 2, 3, 4, 5, 6};
    const std::string path = scratchPath("threads.h5");
    REQUIRE(writeQuantityFile(path, {depth}, 0) == "hdf5");
    std::atomic<int> right{0};
    std::vector<std::thread> threads;
    for (int t = 0; t < 8; ++t)
        threads.emplace_back([&] {
            for (int i = 0; i < 4; ++i) right += read(path).value[5] == 6.0;
        });
    for (std::thread& thread : threads) thread.join();
    REQUIRE(right == 32);

    // Whatever the reader does, zcheck refuses the file and goes on: it crashes, answers in
    // another protocol, or is missing.
    const auto withReader = [&](const std::string& script) {
        const std::string program = scratchPath("reader.sh");
        std::ofstream(program) << "#!/bin/sh\n" << script << "\n";
        fs::permissions(program, fs::perms::owner_all);
        ::setenv("ZCHECK_HDF5_READER", program.c_str(), 1);
        std::string what;
        try {
            (void)read(path);
        } catch (const Error& e) {
            what = e.what();
        }
        ::unsetenv("ZCHECK_HDF5_READER");
        return what;
    };
    REQUIRE_THAT(withReader("kill -SEGV $$"), Catch::Contains("cannot read depth map '" + path + "'") &&
                                                   Catch::Contains("crashed reading it (signal 11)"));
    REQUIRE_THAT(withReader("printf 'something else entirely, long enough for a header'"),
                 Catch::Contains("answered in another protocol"));
    REQUIRE_THAT(withReader("exit 0"), Catch::Contains("stopped before it answered"));
    ::setenv("ZCHECK_HDF5_READER", "/nonexistent/zcheck-hdf5-reader", 1);
    REQUIRE_THROWS_WITH(read(path), Catch::Contains("cannot start /nonexistent/zcheck-hdf5-reader"));
    ::unsetenv("ZCHECK_HDF5_READER");
    REQUIRE(read(path).value[0] == 1.0);
}

namespace {

// A format of this test alone: "FAKE" then nothing; read as a 3x2 map of ones.
DepthMapFile readFake(const std::string&, const DepthMapReading&, int, int)
{
    DepthMapFile map;
    map.width = W, map.height = H;
    map.channel = "Y";
    map.value.assign(std::size_t(W) * H, 1.0);
    return map;
}

const DepthMapFormat kFake{"fake", "a test's own format", {".fake"}, "nothing",
                           [](std::string_view head) { return head.substr(0, 4) == "FAKE"; }, readFake};

}  // namespace

TEST_CASE("regression: concurrent first reads failed while the loader of more formats was running", "[depthmap]")
{
    // The command line loads OpenImageIO's formats on the first file none of its own claims; the
    // readers on other threads must wait for them, not refuse their files meanwhile.
    const std::string path = bytesFile("map.fake", "FAKE");
    setDepthMapFormatLoader([] {
        std::this_thread::sleep_for(std::chrono::milliseconds(300));
        registerDepthMapFormat(kFake);
    });
    std::atomic<int> read{0};
    std::vector<std::thread> threads;
    for (int t = 0; t < 8; ++t)
        threads.emplace_back([&] { read += readDepthMapFile(path, {}, W, H).value.size() == std::size_t(W) * H; });
    for (std::thread& thread : threads) thread.join();
    REQUIRE(read == 8);
    setDepthMapFormatLoader(nullptr);
}
