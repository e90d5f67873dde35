#include "zcheck/atomic_file.h"

#include "zcheck/error.h"

#include <atomic>
#include <filesystem>
#include <fstream>
#include <unistd.h>

namespace zcheck {

void writeAtomically(const std::string& path, const std::function<void(const std::string&)>& write)
{
    namespace fs = std::filesystem;
    static std::atomic<unsigned> counter{0};
    const fs::path target(path);
    const fs::path temporary = target.parent_path() / ("." + target.stem().string() + ".tmp" +
                                                       std::to_string(::getpid()) + "-" +
                                                       std::to_string(counter++) + target.extension().string());
    try {
        write(temporary.string());
        std::error_code ec;
        fs::rename(temporary, target, ec);
        if (ec) throw Error("cannot write '" + path + "': " + ec.message());
    } catch (...) {
        std::error_code ignored;
        fs::remove(temporary, ignored);
        throw;
    }
}

void writeTextFileAtomically(const std::string& path, const std::string& contents)
{
    writeAtomically(path, [&](const std::string& temporary) {
        std::ofstream out(temporary, std::ios::binary);
        out << contents;
        out.flush();
        if (!out) throw Error("cannot write '" + path + "': write failed");
    });
}

}  // namespace zcheck
