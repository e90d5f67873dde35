#include "plugin.h"

#include <dlfcn.h>
#include <unistd.h>

#include <climits>
#include <stdexcept>
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

}  // namespace

void* pluginEntry(const std::string& library, const char* entry)
{
    const std::string dir = executableDirectory();
    const std::vector<std::string> candidates = {dir + "/" + library, dir + "/" ZCHECK_PLUGINS_FROM_BINDIR "/" + library};
    std::string tried;
    for (const std::string& path : candidates) {
        if (void* handle = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL)) {
            if (void* symbol = ::dlsym(handle, entry)) return symbol;
            tried += (tried.empty() ? "" : "; ") + path + ": no entry point " + entry;
            continue;
        }
        const char* why = ::dlerror();
        tried += (tried.empty() ? "" : "; ") + (why ? std::string(why) : path);
    }
    throw std::runtime_error("cannot load the plugin " + library + " (" + tried + ")");
}

}  // namespace zcheck::cli
