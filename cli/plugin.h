#pragma once
// The zcheck executable's plugins: shared libraries it loads only when a command needs them, so
// that it links none of their dependencies (libzcheck_images.so: OpenImageIO, image_plugin.h;
// libzcheck_gl_yardstick.so: Mesa's EGL, for `bench --reference`). A plugin is looked for next
// to the executable (the build tree), then at the install's relative location (bin/../lib/zcheck).
#include <string>

namespace zcheck::cli {

// The address of `entry` in plugin `library` ("libzcheck_images.so"), loaded once per process
// (dlopen keeps it). Throws std::runtime_error naming every path tried and why it failed.
void* pluginEntry(const std::string& library, const char* entry);

}  // namespace zcheck::cli
