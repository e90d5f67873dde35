#pragma once
// Input files, read whole and checked before any parser sees them.
//
// Every input zcheck reads (mesh, camera file, depth map, sidecar) must be a regular file
// (not a directory, FIFO, socket or device: a FIFO would block forever) no larger than the
// limit for its kind. Violations throw Error naming the kind, the path and the rule.
#include "zcheck/large_buffer.h"

#include <cstdint>
#include <string>

namespace zcheck {

struct InputKind {
    const char* name;        // "mesh", "camera file", ... as messages say it
    std::uint64_t maxBytes;  // larger files are refused before they are read
};
inline constexpr InputKind kMeshInput{"mesh", std::uint64_t(4) << 30};           // 4 GiB
inline constexpr InputKind kCameraInput{"camera file", std::uint64_t(1) << 20};  // 1 MiB
inline constexpr InputKind kDepthMapInput{"depth map", std::uint64_t(2) << 30};  // 2 GiB
inline constexpr InputKind kSidecarInput{"sidecar", std::uint64_t(1) << 20};     // 1 MiB
// Files of many cameras: a transforms.json of thousands of frames (JSON is held as a DOM of a
// few times its size), a COLMAP model's files (images.bin holds every 2-D observation).
inline constexpr InputKind kCameraSetInput{"camera file", std::uint64_t(512) << 20};       // 512 MiB
inline constexpr InputKind kColmapModelInput{"COLMAP model file", std::uint64_t(4) << 30};  // 4 GiB
inline constexpr InputKind kManifestInput{"manifest", std::uint64_t(512) << 20};            // 512 MiB
inline constexpr InputKind kResultsInput{"results file", std::uint64_t(4) << 30};           // 4 GiB

// Throws Error unless `path` names a readable regular file within the kind's size limit;
// returns its size in bytes.
std::uint64_t checkInputFile(const std::string& path, const InputKind& kind);

// checkInputFile, then the whole content. A short read is an Error, not a shorter string.
std::string readInputFile(const std::string& path, const InputKind& kind);
// The same into a LargeVector: for files of tens of megabytes (meshes), whose buffer is then
// faulted in on huge pages by the read itself instead of zeroed first 4 KiB at a time.
LargeVector<char> readInputBytes(const std::string& path, const InputKind& kind);

// The file name's extension in lower case with its dot (".ply"), or "" if it has none.
std::string lowerExtension(const std::string& path);

}  // namespace zcheck
