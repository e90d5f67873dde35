#include "image_plugin.h"

#include "plugin.h"

#include <mutex>

namespace zcheck::cli {

const ImageFunctions& images()
{
    static std::once_flag once;
    static const ImageFunctions* functions = nullptr;
    std::call_once(once, [] {
        using Entry = const ImageFunctions* (*)();
        functions = reinterpret_cast<Entry>(pluginEntry("libzcheck_images.so", "zcheck_image_functions"))();
    });
    return *functions;
}

DepthMapFile readDepthMapFile(const std::string& path, const DepthMapReading& reading, int width, int height)
{
    if (std::optional<DepthMapFile> native = readDepthMapNatively(path, reading, width, height)) return std::move(*native);
    return images().readDepthMap(path, reading, width, height);
}

}  // namespace zcheck::cli
