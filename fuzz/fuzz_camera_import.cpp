// libFuzzer harness for the camera formats and dataset sources (camera_formats.h,
// dataset_source.h): every row of the table, and manifests. An input is the format's name on
// its first line, then the file's bytes: "nerfstudio\n{...}", "manifest\n{...}". A one-file
// format's reader is fed the bytes directly (CameraFormat::parse); a COLMAP model is two files:
// "colmap-text" or "colmap-bin", the rest split at the first "\n--8<--\n" into cameras and
// images, written to a folder. Every camera read is also selected by FILE#FRAME and built, as
// zcheck would, and a dataset source is opened as a dataset. A new format needs no change here:
// a seed named after it (fuzz/corpus/camera_import/NAME) is enough.
#include "zcheck/camera_formats.h"
#include "zcheck/camera_import.h"
#include "zcheck/dataset_source.h"
#include "zcheck/error.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

namespace {

void write(const std::string& path, const std::string& bytes)
{
    std::FILE* file = std::fopen(path.c_str(), "wb");
    if (!file) return;
    std::fwrite(bytes.data(), 1, bytes.size(), file);
    std::fclose(file);
}

void exercise(const zcheck::CameraSet& set)
{
    for (const char* frame : {"", "0", "1", "frame_000.png", "img", "raw", "rectified"}) {
        try {
            const zcheck::ImportedCamera& camera = set.cameras.at(set.find(frame));
            zcheck::CameraSpec spec = camera.spec;
            if (camera.projectionForSize) spec.projection = camera.projectionForSize(64, 48), spec.width = 64, spec.height = 48;
            const zcheck::Camera built(spec);
        } catch (const zcheck::Error&) {
        }
    }
}

void readAs(const zcheck::CameraFormat& format, const std::string& path, const std::string& bytes)
{
    if (format.parse) {
        exercise(format.parse(bytes, path));
    } else {
        exercise(zcheck::readCameraSet(path, &format));
    }
    if (format.datasetSource) {
        if (format.parse) write(path, bytes);
        zcheck::DatasetSourceOptions options;
        options.cameraFormat = &format;
        if (!format.namesDepthMaps) options.depthPattern = "depth/{stem}.bin";
        (void)zcheck::openDataset(path, options);
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    static const std::string dir = "/tmp/zcheck-fuzz-import-" + std::to_string(::getpid());
    static const bool made = ::mkdir(dir.c_str(), 0700) == 0 || true;
    (void)made;
    const std::string input(reinterpret_cast<const char*>(data), size);
    const std::size_t newline = input.find('\n');
    if (newline == std::string::npos) return 0;
    const std::string name = input.substr(0, newline), body = input.substr(newline + 1);
    for (const char* file : {"cameras.txt", "images.txt", "cameras.bin", "images.bin"}) std::remove((dir + "/" + file).c_str());
    try {
        if (name == "colmap-text" || name == "colmap-bin") {
            const std::size_t cut = body.find("\n--8<--\n");
            const std::string suffix = name == "colmap-bin" ? ".bin" : ".txt";
            write(dir + "/cameras" + suffix, body.substr(0, cut));
            write(dir + "/images" + suffix, cut == std::string::npos ? "" : body.substr(cut + 8));
            readAs(zcheck::cameraFormatNamed("colmap"), dir, "");
        } else if (name == "manifest") {
            write(dir + "/manifest.jsonl", body);
            (void)zcheck::openDataset(dir + "/manifest.jsonl", {});
        } else {
            const zcheck::CameraFormat* format = nullptr;
            for (const zcheck::CameraFormat* row : zcheck::cameraFormats())
                if (row->name == name) format = row;
            if (!format) return 0;
            readAs(*format, dir + "/input", body);
        }
    } catch (const zcheck::Error&) {
    }
    // Telling the format by content must never throw anything but Error either.
    try {
        (void)zcheck::detectCameraFormat(dir + "/input");
    } catch (const zcheck::Error&) {
    }
    return 0;
}
