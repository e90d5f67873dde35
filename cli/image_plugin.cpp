#include "image_plugin.h"

#include <dlfcn.h>
#include <unistd.h>

#include <climits>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

namespace zcheck::cli {

namespace {

std::string executableDirectory()
{
    char path[PATH_MAX];
    const ssize_t length = ::readlink("/proc/self/exe", path, sizeof path - 1);
    if (length <= 0) return ".";
    const std::string exe(path, std::size_t(length));
    const std::size_t slash = exe.rfind('/');
    return slash == std::string::npos ? "." : exe.substr(0, slash);
}

const ImageFunctions* load()
{
    const std::string dir = executableDirectory();
    const std::vector<std::string> candidates = {dir + "/libzcheck_images.so",
                                                 dir + "/" ZCHECK_IMAGE_PLUGIN_FROM_BINDIR "/libzcheck_images.so"};
    std::string tried;
    for (const std::string& path : candidates) {
        if (void* handle = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL)) {
            using Entry = const ImageFunctions* (*)();
            if (auto entry = reinterpret_cast<Entry>(::dlsym(handle, "zcheck_image_functions"))) return entry();
            tried += (tried.empty() ? "" : "; ") + path + ": no entry point";
            continue;
        }
        const char* why = ::dlerror();
        tried += (tried.empty() ? "" : "; ") + (why ? std::string(why) : path);
    }
    throw std::runtime_error("cannot load the image plugin libzcheck_images.so (" + tried + ")");
}

}  // namespace

const ImageFunctions& images()
{
    static std::once_flag once;
    static const ImageFunctions* functions = nullptr;
    std::call_once(once, [] { functions = load(); });
    return *functions;
}

DepthMapFile readDepthMapFile(const std::string& path, const DepthMapReading& reading, int width, int height)
{
    if (std::optional<DepthMapFile> native = readDepthMapNatively(path, reading, width, height)) return std::move(*native);
    return images().readDepthMap(path, reading, width, height);
}

}  // namespace zcheck::cli
