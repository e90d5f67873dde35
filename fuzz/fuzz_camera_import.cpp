// libFuzzer harness for the camera importers and dataset sources (camera_import.h,
// dataset_source.h): COLMAP text and binary models, transforms.json, OpenCV FileStorage YAML and
// XML, ROS CameraInfo, manifests. The first byte chooses the format; for the two-file COLMAP
// models the rest is split at the first "\n--8<--\n" into cameras and images. Every camera read
// is also selected by FILE#FRAME and built, as zcheck would.
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

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    if (size < 1) return 0;
    static const std::string dir = "/tmp/zcheck-fuzz-import-" + std::to_string(::getpid());
    static const bool made = ::mkdir(dir.c_str(), 0700) == 0 || true;
    (void)made;
    const int kind = data[0] % 7;
    const std::string body(reinterpret_cast<const char*>(data) + 1, size - 1);
    const std::size_t cut = body.find("\n--8<--\n");
    const std::string first = cut == std::string::npos ? body : body.substr(0, cut);
    const std::string second = cut == std::string::npos ? "" : body.substr(cut + 8);
    for (const char* name : {"cameras.txt", "images.txt", "cameras.bin", "images.bin"}) std::remove((dir + "/" + name).c_str());
    try {
        switch (kind) {
        case 0:
        case 1: {
            const bool binary = kind == 1;
            write(dir + (binary ? "/cameras.bin" : "/cameras.txt"), first);
            write(dir + (binary ? "/images.bin" : "/images.txt"), second);
            exercise(zcheck::readCameraSet(dir, zcheck::CameraFormat::Colmap));
            zcheck::DatasetSourceOptions options;
            options.depthPattern = "depth/{stem}.bin";
            (void)zcheck::openDataset(dir, options);
            break;
        }
        case 2:
            write(dir + "/transforms.json", body);
            exercise(zcheck::readCameraSet(dir + "/transforms.json", zcheck::CameraFormat::Nerfstudio));
            (void)zcheck::openDataset(dir + "/transforms.json", {});
            break;
        case 3:
        case 4:
            write(dir + "/calibration", body);
            exercise(zcheck::readCameraSet(dir + "/calibration", zcheck::CameraFormat::OpenCv));
            break;
        case 5:
            write(dir + "/camera_info.yaml", body);
            exercise(zcheck::readCameraSet(dir + "/camera_info.yaml", zcheck::CameraFormat::Ros));
            break;
        default:
            write(dir + "/manifest.jsonl", body);
            (void)zcheck::openDataset(dir + "/manifest.jsonl", {});
            break;
        }
    } catch (const zcheck::Error&) {
    }
    // Telling the format by content must never throw anything but Error either.
    try {
        (void)zcheck::detectCameraFormat(dir + "/transforms.json");
    } catch (const zcheck::Error&) {
    }
    return 0;
}
