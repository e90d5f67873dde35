// HDF5 depth maps (depth_formats.h). The HDF5 library trusts the file's structure more than a
// checker may: malformed files have crashed and hung it (its CVE list is long). So the file is
// read by a program of its own, zcheck-hdf5-reader (hdf5_reader/main.cpp), started with
// posix_spawn — a fork of this multithreaded process (TBB's workers in `dataset verify`) could
// deadlock in the child — which sends back the dataset's values or one line saying why not; a
// reader that dies, takes longer than kReaderSeconds or answers garbled turns into a refusal
// naming the file, never into a crash or a hang of zcheck. Writing (export) happens in this
// process: zcheck makes those files itself.
#include "depth_formats.h"
#include "hdf5_reply.h"

#include "zcheck/error.h"
#include "zcheck/input_file.h"

#include <hdf5.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <poll.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace zcheck::depthformats {

namespace {

constexpr int kReaderSeconds = 60;

// The reader program: $ZCHECK_HDF5_READER, else the one this build made, else the installed one.
std::string readerProgram()
{
    if (const char* given = std::getenv("ZCHECK_HDF5_READER"); given && *given) return given;
    for (const char* candidate : {ZCHECK_HDF5_READER_BUILT, ZCHECK_HDF5_READER_INSTALLED})
        if (::access(candidate, X_OK) == 0) return candidate;
    throw Error(std::string("cannot read HDF5 depth maps: the reader program is missing (looked for ") +
                ZCHECK_HDF5_READER_BUILT + " and " + ZCHECK_HDF5_READER_INSTALLED + "; ZCHECK_HDF5_READER names another)");
}

// The reader started on `path` with its standard output on a pipe (returned: its pid and the
// pipe's reading end); its standard input and error are /dev/null.
std::pair<pid_t, int> startReader(const std::string& path, const DepthMapReading& reading, int expectedWidth,
                                  int expectedHeight)
{
    const std::string program = readerProgram();
    int pipeFds[2];
    if (::pipe2(pipeFds, O_CLOEXEC) != 0) throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_adddup2(&actions, pipeFds[1], STDOUT_FILENO);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
    const std::string width = std::to_string(expectedWidth), height = std::to_string(expectedHeight);
    const std::string scaleGiven = reading.scale > 0 ? "1" : "0";
    const char* argv[] = {program.c_str(), path.c_str(), reading.channel.c_str(), reading.quantityChannel.c_str(),
                          width.c_str(), height.c_str(), scaleGiven.c_str(), nullptr};
    pid_t child = 0;
    const int failed = ::posix_spawn(&child, program.c_str(), &actions, nullptr, const_cast<char* const*>(argv), environ);
    posix_spawn_file_actions_destroy(&actions);
    ::close(pipeFds[1]);
    if (failed != 0) {
        ::close(pipeFds[0]);
        throw std::runtime_error("cannot start " + program + ": " + std::strerror(failed));
    }
    return {child, pipeFds[0]};
}

// Everything the reader writes until it closes its output, or until kReaderSeconds have passed
// (`timedOut`).
std::string answerOf(int fd, bool& timedOut)
{
    std::string received;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(kReaderSeconds);
    char buffer[1 << 16];
    timedOut = false;
    while (true) {
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()).count();
        if (left <= 0) {
            timedOut = true;
            return received;
        }
        pollfd p{fd, POLLIN, 0};
        const int ready = ::poll(&p, 1, int(std::min<long long>(left, 1000)));
        if (ready < 0 && errno == EINTR) continue;
        if (ready == 0) continue;
        const ssize_t n = ::read(fd, buffer, sizeof buffer);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return received;
        received.append(buffer, std::size_t(n));
    }
}

// Closes an HDF5 handle on scope exit.
struct Handle {
    hid_t id;
    herr_t (*close)(hid_t);
    ~Handle()
    {
        if (id >= 0) close(id);
    }
};

}  // namespace

DepthMapFile readHdf5(const std::string& path, const DepthMapReading& reading, int expectedWidth, int expectedHeight)
{
    checkInputFile(path, kDepthMapInput);
    const auto [child, fd] = startReader(path, reading, expectedWidth, expectedHeight);
    bool timedOut = false;
    const std::string received = answerOf(fd, timedOut);
    ::close(fd);
    if (timedOut) ::kill(child, SIGKILL);
    int status = 0;
    while (::waitpid(child, &status, 0) < 0 && errno == EINTR) {
    }
    auto refuse = [&](const std::string& why) -> DepthMapFile { throw Error("cannot read depth map '" + path + "': " + why); };
    if (timedOut) return refuse("the HDF5 library did not finish reading it in " + std::to_string(kReaderSeconds) + " s (malformed HDF5?)");
    if (WIFSIGNALED(status))
        return refuse("the HDF5 library crashed reading it (signal " + std::to_string(WTERMSIG(status)) + "): malformed HDF5");
    Hdf5Reply reply;
    if (received.size() < sizeof reply) return refuse("the HDF5 reader stopped before it answered (malformed HDF5?)");
    std::memcpy(&reply, received.data(), sizeof reply);
    if (std::memcmp(reply.magic, Hdf5Reply().magic, sizeof reply.magic) != 0)
        return refuse("the HDF5 reader program answered in another protocol (a reader of another zcheck version?)");
    if (received.size() < sizeof reply + reply.textBytes) return refuse("the HDF5 reader's answer is cut short");
    const std::string text = received.substr(sizeof reply, reply.textBytes);
    if (!reply.ok) throw Error(text);
    const std::size_t pixels = std::size_t(reply.width) * std::size_t(reply.height);
    if (received.size() != sizeof reply + reply.textBytes + pixels * sizeof(double))
        return refuse("the HDF5 reader's answer is cut short");
    DepthMapFile map;
    map.width = reply.width, map.height = reply.height, map.channel = text;
    map.value.resize(pixels);
    std::memcpy(map.value.data(), received.data() + sizeof reply + reply.textBytes, pixels * sizeof(double));
    depthsFromStored(map, reply.integer ? StoredValues::Integer : StoredValues::Float, reading);
    return map;
}

void writeHdf5(const std::string& path, const std::vector<QuantityImage>& images)
{
    auto fail = [&](const std::string& why) { throw Error("cannot write '" + path + "': " + why); };
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    const Handle file{H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose};
    if (file.id < 0) fail("the HDF5 library cannot create it");
    for (const QuantityImage& image : images) {
        const std::size_t channels = image.quantity == ExportQuantity::PrimitiveId ? 1 : image.channels.size();
        const hsize_t dims[3] = {hsize_t(image.height), hsize_t(image.width), hsize_t(channels)};
        const Handle space{H5Screate_simple(channels == 1 ? 2 : 3, dims, nullptr), H5Sclose};
        const bool ids = image.quantity == ExportQuantity::PrimitiveId;
        // One dataset per quantity, named by its channel (or, for several, the quantity's name).
        const std::string name = channels == 1 ? image.channels.front() : toString(image.quantity);
        const Handle dataset{H5Dcreate2(file.id, name.c_str(), ids ? H5T_STD_U32LE : H5T_IEEE_F32LE, space.id, H5P_DEFAULT,
                                        H5P_DEFAULT, H5P_DEFAULT),
                             H5Dclose};
        if (dataset.id < 0) fail("the HDF5 library cannot create the dataset '" + name + "'");
        herr_t written;
        if (ids) {
            written = H5Dwrite(dataset.id, H5T_NATIVE_UINT32, H5S_ALL, H5S_ALL, H5P_DEFAULT, image.id.data());
        } else {
            written = H5Dwrite(dataset.id, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, image.value.data());
        }
        if (written < 0) fail("the HDF5 library cannot write the dataset '" + name + "'");
    }
    if (H5Fflush(file.id, H5F_SCOPE_GLOBAL) < 0) fail("the HDF5 library cannot flush it");
}

const DepthMapFormat& hdf5Format()
{
    static const DepthMapFormat row{
        "hdf5", "HDF5", {".h5", ".hdf5"}, "any quantities, one float32 dataset each named by its channel (ids uint32)", isHdf5,
        readHdf5, [](const std::string& path, const std::vector<QuantityImage>& images, double) { writeHdf5(path, images); },
        true};
    return row;
}

}  // namespace zcheck::depthformats
