#pragma once
// What the HDF5 reader program (hdf5_reader/main.cpp) answers readHdf5 (depth_hdf5.cpp) on its
// standard output: this header, then `textBytes` of text (the dataset's name, or the one-line
// error), then width × height doubles in native byte order (the same machine, the same build).
// Private to zcheck::depthmaps.
#include <cstdint>

namespace zcheck::depthformats {

struct Hdf5Reply {
    char magic[8] = {'z', 'c', 'h', 'd', 'f', '5', '/', '1'};  // the protocol and its version
    std::int32_t ok = 0;
    std::int32_t width = 0, height = 0;
    std::int32_t integer = 0;  // the dataset stores integers
    std::uint32_t textBytes = 0;
};

}  // namespace zcheck::depthformats
