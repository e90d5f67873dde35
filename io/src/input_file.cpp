#include "zcheck/input_file.h"

#include "zcheck/detail/streaming_stores.h"
#include "zcheck/error.h"
#include "zcheck/large_buffer.h"

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace zcheck {

namespace {

std::string sizeText(std::uint64_t bytes)
{
    if (bytes >= (std::uint64_t(1) << 30) && bytes % (std::uint64_t(1) << 30) == 0)
        return std::to_string(bytes >> 30) + " GiB";
    if (bytes >= (std::uint64_t(1) << 20) && bytes % (std::uint64_t(1) << 20) == 0)
        return std::to_string(bytes >> 20) + " MiB";
    return std::to_string(bytes) + " bytes";
}

[[noreturn]] void refuse(const std::string& path, const InputKind& kind, const std::string& why)
{
    throw Error(std::string("cannot read ") + kind.name + " '" + path + "': " + why);
}

}  // namespace

std::uint64_t checkInputFile(const std::string& path, const InputKind& kind)
{
    if (path.empty()) throw Error(std::string("the ") + kind.name + " path is empty");
    struct stat status {};
    if (::stat(path.c_str(), &status) != 0) refuse(path, kind, std::strerror(errno));
    if (S_ISDIR(status.st_mode)) refuse(path, kind, "it is a directory");
    if (!S_ISREG(status.st_mode)) refuse(path, kind, "not a regular file (a FIFO, socket or device is not read)");
    const auto size = static_cast<std::uint64_t>(status.st_size);
    if (size > kind.maxBytes)
        refuse(path, kind, "it is " + std::to_string(size) + " bytes, over the " + sizeText(kind.maxBytes) + " limit for a " +
                               kind.name);
    return size;
}

namespace {

// checkInputFile, then the whole content into a Bytes (std::string or LargeVector<char>).
template <class Bytes>
Bytes readWhole(const std::string& path, const InputKind& kind)
{
    checkInputFile(path, kind);
    // O_NONBLOCK: should the path have been swapped for a FIFO since the check, open does
    // not wait for a writer; fstat then refuses it.
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) refuse(path, kind, std::strerror(errno));
    struct stat status {};
    if (::fstat(fd, &status) != 0 || !S_ISREG(status.st_mode)) {
        ::close(fd);
        refuse(path, kind, "not a regular file");
    }
    const auto size = static_cast<std::uint64_t>(status.st_size);
    if (size > kind.maxBytes) {
        ::close(fd);
        refuse(path, kind, "it grew over the " + sizeText(kind.maxBytes) + " limit while being read");
    }
    Bytes bytes;
    bytes.reserve(size);
    adviseHugePages(bytes.data(), size);  // for std::string (a LargeVector advises its own): large_buffer.h
    bytes.resize(size);
    std::uint64_t done = 0;
    while (done < size) {
        const ssize_t n = ::read(fd, bytes.data() + done, size - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            const std::string why = n < 0 ? std::strerror(errno) : "the file shrank while being read";
            ::close(fd);
            refuse(path, kind, why);
        }
        done += std::uint64_t(n);
    }
    ::close(fd);
    return bytes;
}

}  // namespace

std::string readInputFile(const std::string& path, const InputKind& kind) { return readWhole<std::string>(path, kind); }

LargeVector<char> readInputBytes(const std::string& path, const InputKind& kind)
{
    return readWhole<LargeVector<char>>(path, kind);
}

std::string lowerExtension(const std::string& path)
{
    const std::size_t slash = path.find_last_of('/'), dot = path.find_last_of('.');
    if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
    std::string ext = path.substr(dot);
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

}  // namespace zcheck
