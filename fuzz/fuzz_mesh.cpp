// libFuzzer harness for zcheck's mesh readers (mesh_formats.h). One source, one executable
// per format: ZCHECK_FUZZ_FORMAT selects the reader. Any exception but zcheck::Error, any
// crash, sanitizer report, leak or hang is a finding.
#include "zcheck/error.h"
#include "zcheck/mesh_formats.h"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string bytes(reinterpret_cast<const char*>(data), size);
    try {
#if ZCHECK_FUZZ_FORMAT == 1
        zcheck::readPly("fuzz.ply", bytes);
#elif ZCHECK_FUZZ_FORMAT == 2
        zcheck::readObj("fuzz.obj", bytes);
#elif ZCHECK_FUZZ_FORMAT == 3
        zcheck::readStl("fuzz.stl", bytes);
#elif ZCHECK_FUZZ_FORMAT == 4
        zcheck::readGltf("fuzz.glb", bytes);
#endif
    } catch (const zcheck::Error&) {
    }
    return 0;
}
