// HDF5 depth maps (depth_formats.h). The HDF5 library trusts the file's structure more than a
// checker may: malformed files have crashed and hung it (its CVE list is long). So the file is
// read in a child process, which sends back the dataset's values or one line saying why not;
// a child that dies or takes longer than kChildSeconds turns into a refusal naming the file,
// never into a crash or a hang of zcheck. Writing (export) happens in this process: zcheck
// makes those files itself.
#include "depth_formats.h"

#include "zcheck/camera.h"
#include "zcheck/error.h"
#include "zcheck/input_file.h"

#include <hdf5.h>

#include <cerrno>
#include <fcntl.h>
#include <csignal>
#include <cstring>
#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>

namespace zcheck::depthformats {

namespace {

constexpr int kChildSeconds = 60;

// What the child sends: a header, the message (an error) or the channel name, then the values.
struct Reply {
    std::int32_t ok = 0;
    std::int32_t width = 0, height = 0;
    std::int32_t integer = 0;
    std::uint32_t textBytes = 0;
};

// The datasets of a file, by path without the leading '/'.
herr_t collectDataset(hid_t, const char* name, const H5O_info_t* info, void* out)
{
    if (info->type == H5O_TYPE_DATASET && std::strcmp(name, ".") != 0) {
        auto* names = static_cast<std::vector<std::string>*>(out);
        if (names->size() < 4096) names->push_back(name);
    }
    return 0;
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

// The child's work, in this process's terms: the chosen dataset's values as doubles.
DepthMapFile readInProcess(const std::string& path, const DepthMapReading& reading, int expectedWidth, int expectedHeight,
                           bool& integer)
{
    auto refuse = [&](const std::string& why) { throw Error("cannot read depth map '" + path + "': " + why); };
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // errors come back as return values, not prints
    const Handle file{H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
    if (file.id < 0) refuse("the HDF5 library cannot open it (malformed HDF5)");
    std::vector<std::string> names;
    if (H5Ovisit2(file.id, H5_INDEX_NAME, H5_ITER_NATIVE, collectDataset, &names, H5O_INFO_BASIC) < 0)
        refuse("the HDF5 library cannot walk its groups (malformed HDF5)");
    if (names.empty()) refuse("the HDF5 file holds no dataset");
    DepthMapFile map;
    map.channel = chooseDepthChannel(path, names, reading.channel, reading.quantityChannel);
    const Handle dataset{H5Dopen2(file.id, map.channel.c_str(), H5P_DEFAULT), H5Dclose};
    if (dataset.id < 0) refuse("its dataset '" + map.channel + "' cannot be opened");
    const Handle space{H5Dget_space(dataset.id), H5Sclose};
    const int rank = space.id < 0 ? -1 : H5Sget_simple_extent_ndims(space.id);
    if (rank != 2 && rank != 3)
        refuse("its dataset '" + map.channel + "' has " + std::to_string(rank) +
               " dimensions: a depth map is (height, width) or (height, width, 1)");
    hsize_t dims[3] = {0, 0, 1};
    H5Sget_simple_extent_dims(space.id, dims, nullptr);
    if (rank == 3 && dims[2] != 1)
        refuse("its dataset '" + map.channel + "' has " + std::to_string(dims[2]) + " channels; a depth map has 1");
    if (dims[0] > hsize_t(Camera::kMaxImageSide) || dims[1] > hsize_t(Camera::kMaxImageSide))
        refuse("its dataset '" + map.channel + "' is " + std::to_string(dims[1]) + "x" + std::to_string(dims[0]) +
               ", beyond " + std::to_string(Camera::kMaxImageSide) + " pixels per side");
    map.height = int(dims[0]), map.width = int(dims[1]);
    if (expectedWidth == 0 && expectedHeight == 0) {
        if (!Camera::isImageSize(map.width, map.height))
            refuse("its dataset is " + std::to_string(map.width) + "x" + std::to_string(map.height) +
                   ", outside the sizes a camera may have");
    } else if (map.width != expectedWidth || map.height != expectedHeight) {
        throw Error("depth map '" + path + "' is " + std::to_string(map.width) + "x" + std::to_string(map.height) +
                    " but the camera's image is " + std::to_string(expectedWidth) + "x" + std::to_string(expectedHeight));
    }
    const Handle type{H5Dget_type(dataset.id), H5Tclose};
    const H5T_class_t kind = type.id < 0 ? H5T_NO_CLASS : H5Tget_class(type.id);
    const std::size_t bytes = type.id < 0 ? 0 : H5Tget_size(type.id);
    if (kind != H5T_FLOAT && kind != H5T_INTEGER)
        refuse("its dataset '" + map.channel + "' holds neither floats nor integers");
    integer = kind == H5T_INTEGER;
    if (integer && bytes < 2)
        refuse("its dataset '" + map.channel + "' stores 8-bit integers, which cannot hold depth (a picture, not a depth map?)");
    if (integer && !(reading.scale > 0))
        throw Error("depth map '" + path + "' stores integers (HDF5 dataset '" + map.channel +
                    "'): give --scale (stored value = depth × scale, e.g. 1000 for millimetres)");
    map.value.resize(std::size_t(map.width) * std::size_t(map.height));
    if (H5Dread(dataset.id, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, map.value.data()) < 0)
        refuse("the HDF5 library cannot read its dataset '" + map.channel + "' (truncated or corrupt)");
    return map;
}

bool writeAll(int fd, const void* data, std::size_t size)
{
    const char* p = static_cast<const char*>(data);
    while (size > 0) {
        const ssize_t n = ::write(fd, p, size);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return false;
        p += n, size -= std::size_t(n);
    }
    return true;
}

}  // namespace

DepthMapFile readHdf5(const std::string& path, const DepthMapReading& reading, int expectedWidth, int expectedHeight)
{
    checkInputFile(path, kDepthMapInput);
    int pipeFds[2];
    if (::pipe2(pipeFds, O_CLOEXEC) != 0) throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
    const pid_t child = ::fork();
    if (child < 0) {
        ::close(pipeFds[0]), ::close(pipeFds[1]);
        throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
    }
    if (child == 0) {
        ::close(pipeFds[0]);
        Reply reply;
        std::string text;
        std::vector<double> values;
        try {
            bool integer = false;
            DepthMapFile map = readInProcess(path, reading, expectedWidth, expectedHeight, integer);
            reply.ok = 1, reply.width = map.width, reply.height = map.height, reply.integer = integer;
            text = map.channel;
            values = std::move(map.value);
        } catch (const std::exception& e) {
            text = e.what();
        }
        reply.textBytes = std::uint32_t(text.size());
        const bool sent = writeAll(pipeFds[1], &reply, sizeof reply) && writeAll(pipeFds[1], text.data(), text.size()) &&
                          writeAll(pipeFds[1], values.data(), values.size() * sizeof(double));
        ::_exit(sent ? 0 : 1);
    }
    ::close(pipeFds[1]);
    // Read the reply, giving up after kChildSeconds.
    std::string received;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(kChildSeconds);
    bool timedOut = false;
    char buffer[1 << 16];
    while (true) {
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()).count();
        if (left <= 0) {
            timedOut = true;
            break;
        }
        pollfd p{pipeFds[0], POLLIN, 0};
        const int ready = ::poll(&p, 1, int(std::min<long long>(left, 1000)));
        if (ready < 0 && errno == EINTR) continue;
        if (ready == 0) continue;
        const ssize_t n = ::read(pipeFds[0], buffer, sizeof buffer);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) break;
        received.append(buffer, std::size_t(n));
    }
    ::close(pipeFds[0]);
    if (timedOut) ::kill(child, SIGKILL);
    int status = 0;
    while (::waitpid(child, &status, 0) < 0 && errno == EINTR) {
    }
    auto refuse = [&](const std::string& why) -> DepthMapFile { throw Error("cannot read depth map '" + path + "': " + why); };
    if (timedOut) return refuse("the HDF5 library did not finish reading it in " + std::to_string(kChildSeconds) + " s (malformed HDF5?)");
    if (WIFSIGNALED(status))
        return refuse("the HDF5 library crashed reading it (signal " + std::to_string(WTERMSIG(status)) + "): malformed HDF5");
    Reply reply;
    if (received.size() < sizeof reply) return refuse("the HDF5 reader stopped before it answered (malformed HDF5?)");
    std::memcpy(&reply, received.data(), sizeof reply);
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

}  // namespace zcheck::depthformats
