// libFuzzer harness for the camera file: strict JSON parsing, every key, and the camera's
// validation (a camera that parses is also built, as zcheck would).
#include "zcheck/camera.h"
#include "zcheck/camera_file.h"
#include "zcheck/error.h"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string text(reinterpret_cast<const char*>(data), size);
    try {
        const zcheck::CameraSpec spec = zcheck::cameraSpecFromJsonText(text, "camera file 'fuzz.json'");
        const zcheck::Camera camera(spec);
        (void)zcheck::matricesJsonText(camera);
    } catch (const zcheck::Error&) {
    }
    return 0;
}
