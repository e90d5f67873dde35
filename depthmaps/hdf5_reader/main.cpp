// zcheck-hdf5-reader PATH CHANNEL QUANTITY_CHANNEL WIDTH HEIGHT SCALE_GIVEN: the one program that
// runs libhdf5 on a file zcheck did not write. The HDF5 library trusts a file's structure more
// than a checker may (malformed files have crashed and hung it), so readHdf5 (depth_hdf5.cpp)
// starts this program with posix_spawn — never a bare fork of a multithreaded process — and
// turns a crash, a hang or a garbled answer into a refusal naming the file. The answer is
// hdf5_reply.h's, on standard output; the exit status is 0 when it was written whole.
#include "hdf5_reply.h"
#include "zcheck/camera.h"
#include "zcheck/depth_map_reading.h"
#include "zcheck/error.h"

#include <hdf5.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <string>
#include <unistd.h>
#include <vector>

namespace {

using namespace zcheck;

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

// The chosen dataset's values as doubles; `integer` says whether it stores integers.
DepthMapFile readDataset(const std::string& path, const DepthMapReading& reading, int expectedWidth, int expectedHeight,
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
    if (integer) reading.requireScaleForIntegers(path, "HDF5 dataset '" + map.channel + "'");
    map.value.resize(std::size_t(map.width) * std::size_t(map.height));
    if (H5Dread(dataset.id, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, map.value.data()) < 0)
        refuse("the HDF5 library cannot read its dataset '" + map.channel + "' (truncated or corrupt)");
    return map;
}

bool writeAll(const void* data, std::size_t size)
{
    const char* p = static_cast<const char*>(data);
    while (size > 0) {
        const ssize_t n = ::write(STDOUT_FILENO, p, size);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return false;
        p += n, size -= std::size_t(n);
    }
    return true;
}

}  // namespace

int main(int argc, char** argv)
{
    if (argc != 7) return 2;
    DepthMapReading reading;
    reading.channel = argv[2], reading.quantityChannel = argv[3];
    reading.scale = std::strcmp(argv[6], "1") == 0 ? 1 : 0;  // only whether one was given matters here
    depthformats::Hdf5Reply reply;
    std::string text;
    std::vector<double> values;
    try {
        bool integer = false;
        DepthMapFile map = readDataset(argv[1], reading, std::atoi(argv[4]), std::atoi(argv[5]), integer);
        reply.ok = 1, reply.width = map.width, reply.height = map.height, reply.integer = integer;
        text = map.channel;
        values = std::move(map.value);
    } catch (const std::exception& e) {
        text = e.what();
    }
    reply.textBytes = std::uint32_t(text.size());
    const bool sent = writeAll(&reply, sizeof reply) && writeAll(text.data(), text.size()) &&
                      writeAll(values.data(), values.size() * sizeof(double));
    return sent ? 0 : 1;
}
