#pragma once
// The camera formats, one row each (library zcheck::cameras): a format's name, how its files
// are recognised by content, its reader and its writer. The table is the one place that knows
// the formats: `--camera-format`, `zcheck camera --to`, the command-line help, the docs' table
// (docs/cameras.md) and the bad-input catalogue's list are generated from it.
//
// A format is one file in cameras/src/ (its reader and writer together, with what it shares
// in formats.h) plus one row in camera_formats.cpp. glTF cameras are read with their scene, so
// the scene library registers that row itself (camera_sources.cpp): a program that links
// zcheck::scene knows glTF, one that links zcheck::cameras alone does not.
//
// Detection by content tries the rows in order of `priority` (lower first) and takes the first
// whose `detects` says yes; tests/test_camera_formats.cpp requires every format's fuzz seeds and
// examples to be detected as their own format and as no other with a lower priority.
//
// Thread-safety: rows are registered during static initialisation; reading the table is safe
// from any thread afterwards.
#include "zcheck/camera.h"
#include "zcheck/input_file.h"

#include <string>
#include <string_view>
#include <vector>

namespace zcheck {

struct CameraSet;

// One file a writer produces.
struct CameraFileText {
    std::string fileName;  // the name the format gives the file ("cameras.txt")
    std::string text;
};

// What detection sees: the path and the file's first bytes (a UTF-8 BOM and leading white space
// skipped; "" for a folder). Writers put the keys that tell formats apart near the start.
struct CameraFileHead {
    std::string path;
    std::string_view head;
    bool isFolder = false;
    bool looksLikeJson() const;             // starts with '{' or '[', or the path ends in .json
    bool looksLikeXml() const;              // starts with "<?xml" or '<'
    bool has(std::string_view text) const;  // the head holds `text`
    bool hasKeyLine(std::string_view key) const;  // a YAML line "key:" at a line's start
};

struct CameraFormat {
    std::string name;                  // "colmap": --camera-format, --to, reports, dataset kinds
    std::vector<std::string> aliases;  // other names --camera-format takes ("instant-ngp")
    std::string title;                 // in messages and help: "COLMAP model"
    std::vector<std::string> extensions;  // what its files are usually called (".xml"); detection is by content
    std::string files;                 // what its files look like, for help and docs
    std::string example;               // a reference with #FRAME, for help and docs
    int priority = 0;                  // detection order, lower first
    bool (*detects)(const CameraFileHead& file) = nullptr;
    // A one-file format's reader: every camera of the file's bytes. `path` names the file in
    // messages, and resolves the files it names beside it (depth maps, a stereo pair's
    // extrinsics.yml). The fuzzers feed it bytes directly.
    CameraSet (*parse)(std::string_view bytes, const std::string& path) = nullptr;
    // A format of several files (a COLMAP model folder): every camera of the folder or file
    // `path`. nullptr when `parse` reads the format.
    CameraSet (*read)(const std::string& path) = nullptr;
    InputKind input = kCameraSetInput;  // the size limit of its files, checked before they are read
    // The camera in this format (nullptr: the format is read only). `name` names the frame.
    std::vector<CameraFileText> (*write)(const Camera& camera, const std::string& name) = nullptr;
    bool writesFolder = false;         // the writer's files make a folder (a COLMAP model): --out DIR
    // A dataset source: its frames are a dataset's (dataset_source.h). `namesDepthMaps`: its
    // frames name their depth maps, else `zcheck dataset` needs --depth PATTERN.
    bool datasetSource = false;
    bool namesDepthMaps = false;
};

// Every format, in the table's order (camera_formats.cpp's rows, then the registered ones).
const std::vector<const CameraFormat*>& cameraFormats();
// The format named `name` (or one of its aliases). Throws Error listing the names.
const CameraFormat& cameraFormatNamed(const std::string& name);
// The format of a file or folder, told by content. Throws Error naming the file and the formats
// when it is none of them (or a folder that is no format's).
const CameraFormat& detectCameraFormat(const std::string& path);
// Adds a row (the scene library's glTF); a name already registered throws. Returns true, for
// use in a static initialiser.
bool registerCameraFormat(const CameraFormat& format);

// The names, for help and messages: "zcheck | colmap | nerfstudio (instant-ngp) | ...", of every
// format or only of those that have a writer or are dataset sources.
enum class CameraFormatsWith { Reader, Writer, Dataset };
std::string cameraFormatChoices(CameraFormatsWith which, const std::string& separator = " | ");
// The table as Markdown (docs/cameras.md holds it; a test keeps the two the same).
std::string cameraFormatTable();

// The camera written in `format` (its writer). Throws Error naming the formats that have one.
std::vector<CameraFileText> cameraInFormat(const Camera& camera, const CameraFormat& format, const std::string& name);

}  // namespace zcheck
