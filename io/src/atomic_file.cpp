#include "zcheck/atomic_file.h"

#include "zcheck/error.h"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <sys/stat.h>
#include <unistd.h>

namespace zcheck {

namespace fs = std::filesystem;

namespace {

// The same file, by identity where both exist, else by their absolute, normalised paths.
bool sameFile(const std::string& a, const std::string& b)
{
    struct stat sa {}, sb {};
    if (::stat(a.c_str(), &sa) == 0 && ::stat(b.c_str(), &sb) == 0) return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
    std::error_code ec1, ec2;
    const fs::path ca = fs::weakly_canonical(fs::absolute(a), ec1), cb = fs::weakly_canonical(fs::absolute(b), ec2);
    return !ec1 && !ec2 && ca == cb;
}

std::string folderOf(const std::string& path)
{
    const fs::path parent = fs::path(path).parent_path();
    return parent.empty() ? "." : parent.string();
}

void requireWritableFolder(const std::string& folder, const std::string& option, const std::string& path)
{
    struct stat status {};
    if (::stat(folder.c_str(), &status) != 0)
        throw Error("cannot write " + option + " '" + path + "': folder '" + folder + "' does not exist");
    if (!S_ISDIR(status.st_mode))
        throw Error("cannot write " + option + " '" + path + "': '" + folder + "' is not a folder");
    if (::access(folder.c_str(), W_OK | X_OK) != 0)
        throw Error("cannot write " + option + " '" + path + "': folder '" + folder + "' is not writable");
}

std::string temporarySibling(const std::string& path)
{
    static std::atomic<unsigned> counter{0};
    const fs::path target(path);
    return (target.parent_path() / ("." + target.stem().string() + ".zcheck-tmp" + std::to_string(::getpid()) + "-" +
                                    std::to_string(counter++) + target.extension().string()))
        .string();
}

}  // namespace

void writeFileBytes(const std::string& path, std::string_view bytes)
{
    auto fail = [&](const char* step) {
        throw Error("cannot write '" + path + "': " + step + " failed: " + std::strerror(errno));
    };
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) fail("open");
    std::size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            if (n == 0) errno = EIO;
            const int saved = errno;
            ::close(fd);
            errno = saved;
            fail("write");
        }
        done += std::size_t(n);
    }
    if (::fsync(fd) != 0 && errno != EINVAL) {
        const int saved = errno;
        ::close(fd);
        errno = saved;
        fail("fsync");
    }
    if (::close(fd) != 0) fail("close");
}

OutputFiles::~OutputFiles()
{
    if (committed_) return;
    for (const Output& output : outputs_)
        if (!output.temporary.empty()) ::unlink(output.temporary.c_str());
    for (auto folder = createdFolders_.rbegin(); folder != createdFolders_.rend(); ++folder) ::rmdir(folder->c_str());
}

void OutputFiles::addInput(const std::string& path)
{
    if (!path.empty()) inputs_.push_back(path);
}

void OutputFiles::checkNotInput(const std::string& path, const std::string& option) const
{
    for (const std::string& input : inputs_)
        if (sameFile(input, path))
            throw Error("cannot write " + option + " '" + path + "': it is an input of this run ('" + input +
                        "'); choose another output path");
}

void OutputFiles::add(const std::string& path, const std::string& option)
{
    if (path.empty()) throw Error(option + ": the output path is empty");
    if (path.back() == '/') throw Error("cannot write " + option + " '" + path + "': a file path is needed, not a folder");
    struct stat status {};
    if (::stat(path.c_str(), &status) == 0) {
        if (S_ISDIR(status.st_mode)) throw Error("cannot write " + option + " '" + path + "': it is a folder");
        if (!S_ISREG(status.st_mode))
            throw Error("cannot write " + option + " '" + path + "': it exists and is not a regular file");
    }
    checkNotInput(path, option);
    for (const Output& other : outputs_)
        if (sameFile(other.path, path))
            throw Error("cannot write " + option + " '" + path + "': " + other.option + " writes the same file");
    // A folder registered by addFolder may not exist yet: it is checked there.
    const std::string folder = folderOf(path);
    const bool folderPlanned = std::any_of(plannedFolders_.begin(), plannedFolders_.end(),
                                           [&](const std::string& planned) { return sameFile(planned, folder); });
    if (!folderPlanned) requireWritableFolder(folder, option, path);
    outputs_.push_back({path, option, "", false});
}

void OutputFiles::addFolder(const std::string& path, const std::string& option)
{
    if (path.empty()) throw Error(option + ": the output folder is empty");
    struct stat status {};
    if (::stat(path.c_str(), &status) == 0) {
        if (!S_ISDIR(status.st_mode)) throw Error("cannot write to " + option + " '" + path + "': not a folder");
        if (::access(path.c_str(), W_OK | X_OK) != 0)
            throw Error("cannot write to " + option + " '" + path + "': the folder is not writable");
        return;
    }
    const std::string parent = folderOf(fs::path(path).lexically_normal().string());
    requireWritableFolder(parent, option, path);
    // Files inside it skip the folder check; it is created on the first write.
    plannedFolders_.push_back(path);
}

OutputFiles::Output& OutputFiles::registered(const std::string& path)
{
    for (Output& output : outputs_)
        if (output.path == path) return output;
    throw Error("internal error: output '" + path + "' was not registered before the run");
}

void OutputFiles::write(const std::string& path, const std::function<void(const std::string&)>& writer)
{
    Output& output = registered(path);
    const std::string folder = folderOf(path);
    struct stat status {};
    if (::stat(folder.c_str(), &status) != 0) {
        if (::mkdir(folder.c_str(), 0755) != 0)
            throw Error("cannot create folder '" + folder + "' for '" + path + "': " + std::strerror(errno));
        createdFolders_.push_back(folder);
    }
    if (output.temporary.empty()) output.temporary = temporarySibling(path);
    try {
        writer(output.temporary);
    } catch (const Error& e) {
        // Writers name the file they were given: say the user's path instead.
        std::string message = e.what();
        for (std::size_t at = message.find(output.temporary); at != std::string::npos;
             at = message.find(output.temporary, at + path.size()))
            message.replace(at, output.temporary.size(), path);
        throw Error(message);
    }
    if (::stat(output.temporary.c_str(), &status) != 0 || !S_ISREG(status.st_mode))
        throw Error("cannot write '" + path + "': the writer produced no file");
    output.written = true;
}

void OutputFiles::writeText(const std::string& path, std::string_view contents)
{
    write(path, [&](const std::string& temporary) { writeFileBytes(temporary, contents); });
}

void OutputFiles::commit()
{
    for (const Output& output : outputs_)
        if (!output.written)
            throw Error("internal error: output '" + output.path + "' was registered but not written");
    for (Output& output : outputs_) {
        if (::rename(output.temporary.c_str(), output.path.c_str()) != 0)
            throw Error("cannot write '" + output.path + "': rename failed: " + std::strerror(errno));
        output.temporary.clear();
    }
    committed_ = true;
}

void writeAtomically(const std::string& path, const std::function<void(const std::string&)>& write)
{
    OutputFiles outputs;
    outputs.add(path, "output");
    outputs.write(path, write);
    outputs.commit();
}

void writeTextFileAtomically(const std::string& path, const std::string& contents)
{
    OutputFiles outputs;
    outputs.add(path, "output");
    outputs.writeText(path, contents);
    outputs.commit();
}

}  // namespace zcheck
