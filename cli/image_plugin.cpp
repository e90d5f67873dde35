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

void loadImageFormatsWhenNeeded()
{
    setDepthMapFormatLoader([] {
        const ImageFunctions& plugin = images();
        for (std::size_t i = 0; i < plugin.formatCount; ++i) registerDepthMapFormat(*plugin.formats[i]);
    });
}

}  // namespace zcheck::cli
