// libFuzzer harness for depth-map files (PFM by zcheck's reader; EXR, TIFF, PNG and the rest
// through OpenImageIO). The first two bytes choose the size the camera expects (1..64 each);
// the rest is the file, written to a temporary path because readers take paths.
#include "zcheck/error.h"
#include "zcheck/image_io.h"

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <unistd.h>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    if (size < 2) return 0;
    const int width = 1 + data[0] % 64, height = 1 + data[1] % 64;
    static const std::string path = "/tmp/zcheck-fuzz-depth-" + std::to_string(::getpid()) + ".img";
    std::FILE* file = std::fopen(path.c_str(), "wb");
    if (!file) return 0;
    std::fwrite(data + 2, 1, size - 2, file);
    std::fclose(file);
    // Both channel choices (automatic, and a named one), with and without a scale, offset and miss rule.
    for (double scale : {0.0, 1000.0}) {
        zcheck::DepthMapReading reading;
        reading.quantityChannel = "Z";
        reading.scale = scale;
        if (scale > 0) reading.offset = 0.5, reading.miss = zcheck::MissRule::parse(">=65535");
        for (const char* channel : {"", "Y"}) {
            reading.channel = channel;
            try {
                zcheck::readDepthMap(path, reading, width, height);
            } catch (const zcheck::Error&) {
            }
        }
    }
    std::remove(path.c_str());
    return 0;
}
