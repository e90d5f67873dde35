#include "zcheck/camera_import.h"

#include "camera_importers.h"
#include "zcheck/camera_file.h"
#include "zcheck/error.h"
#include "zcheck/input_file.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fcntl.h>
#include <set>
#include <sys/stat.h>
#include <unistd.h>

namespace zcheck {

std::string toString(CameraFormat format)
{
    switch (format) {
    case CameraFormat::Zcheck: return "zcheck";
    case CameraFormat::Colmap: return "colmap";
    case CameraFormat::Nerfstudio: return "nerfstudio";
    case CameraFormat::OpenCv: return "opencv";
    case CameraFormat::Ros: return "ros";
    case CameraFormat::Gltf: return "gltf";
    }
    return "?";
}

namespace {

constexpr CameraFormat kAllCameraFormats[] = {CameraFormat::Zcheck, CameraFormat::Colmap, CameraFormat::Nerfstudio,
                                              CameraFormat::OpenCv, CameraFormat::Ros,    CameraFormat::Gltf};

}  // namespace

const std::vector<std::string>& cameraFormatNames()
{
    static const std::vector<std::string> names = [] {
        std::vector<std::string> all;
        for (CameraFormat f : kAllCameraFormats) all.push_back(toString(f));
        return all;
    }();
    return names;
}

CameraFormat cameraFormatFromName(const std::string& name)
{
    for (CameraFormat f : kAllCameraFormats)
        if (toString(f) == name) return f;
    if (name == "instant-ngp") return CameraFormat::Nerfstudio;
    throw Error("unknown camera format '" + name + "' (expected zcheck, colmap, nerfstudio, instant-ngp, opencv, ros or gltf)");
}

namespace {

bool exists(const std::string& path)
{
    struct stat status {};
    return ::stat(path.c_str(), &status) == 0;
}

bool isDigits(const std::string& text)
{
    return !text.empty() && std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; });
}

std::string withoutDotSlash(std::string path)
{
    while (path.rfind("./", 0) == 0) path.erase(0, 2);
    return path;
}

// The first bytes of a file (at most `count`), for telling formats apart; "" if unreadable.
std::string headOf(const std::string& path, std::size_t count)
{
    checkInputFile(path, kCameraSetInput);
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) return "";
    std::string head(count, '\0');
    const ssize_t n = ::read(fd, head.data(), count);
    ::close(fd);
    head.resize(n > 0 ? std::size_t(n) : 0);
    return head;
}

std::string skipSpaceAndBom(const std::string& text)
{
    std::size_t at = text.rfind("\xEF\xBB\xBF", 0) == 0 ? 3 : 0;
    while (at < text.size() && std::isspace(static_cast<unsigned char>(text[at]))) ++at;
    return text.substr(at);
}

bool hasKeyLine(const std::string& text, const std::string& key)
{
    // A YAML key at the start of a line: "key:".
    std::size_t at = 0;
    while ((at = text.find(key + ":", at)) != std::string::npos) {
        if (at == 0 || text[at - 1] == '\n') return true;
        at += key.size();
    }
    return false;
}

}  // namespace

std::pair<std::string, std::string> splitCameraReference(const std::string& reference)
{
    const std::size_t hash = reference.rfind('#');
    if (hash == std::string::npos || exists(reference)) return {reference, ""};
    return {reference.substr(0, hash), reference.substr(hash + 1)};
}

CameraFormat detectCameraFormat(const std::string& path)
{
    if (!importers::colmapModelFolder(path).empty()) return CameraFormat::Colmap;
    struct stat status {};
    if (::stat(path.c_str(), &status) == 0 && S_ISDIR(status.st_mode))
        throw Error("'" + path + "' is a directory but not a COLMAP model: a model holds cameras.txt and images.txt, or "
                    "cameras.bin and images.bin");
    // The head is enough: every writer puts these keys near the start of the document.
    const std::string head = skipSpaceAndBom(headOf(path, std::size_t(1) << 20));
    if (head.rfind("glTF", 0) == 0) return CameraFormat::Gltf;
    if (head.rfind("%YAML", 0) == 0 || head.rfind("<?xml", 0) == 0 || head.rfind("<opencv_storage", 0) == 0)
        return CameraFormat::OpenCv;
    if (head.rfind("{", 0) == 0 || head.rfind("[", 0) == 0 || lowerExtension(path) == ".json") {
        // JSON: the keys only each kind has (writers put them near the start); anything else is
        // read as a zcheck camera, whose reader names what is wrong with it.
        if (head.find("\"frames\"") != std::string::npos) return CameraFormat::Nerfstudio;
        if (head.find("\"asset\"") != std::string::npos) return CameraFormat::Gltf;
        if (head.find("\"projection\"") == std::string::npos && head.find("opencv-matrix") != std::string::npos)
            return CameraFormat::OpenCv;
        return CameraFormat::Zcheck;
    }
    for (const char* key : {"K", "k", "P", "p", "camera_matrix", "projection_matrix"})
        if (hasKeyLine(head, key)) return CameraFormat::Ros;
    throw Error("camera file '" + path +
                "' is none of the camera formats zcheck reads (a zcheck camera, a COLMAP model folder, transforms.json, "
                "OpenCV FileStorage YAML/XML, ROS CameraInfo YAML, glTF); name its format with --camera-format");
}

CameraSet readCameraSet(const std::string& path, CameraFormat format)
{
    switch (format) {
    case CameraFormat::Zcheck: {
        CameraSet set;
        set.path = path, set.format = format;
        ImportedCamera camera;
        camera.spec = readCameraFile(path);
        camera.hasClipPlanes = true;
        const std::size_t slash = path.find_last_of('/');
        camera.name = slash == std::string::npos ? path : path.substr(slash + 1);
        set.cameras.push_back(camera);
        return set;
    }
    case CameraFormat::Colmap: return importers::readColmapModel(path);
    case CameraFormat::Nerfstudio: return importers::readTransformsJson(path);
    case CameraFormat::OpenCv:
    case CameraFormat::Ros: return importers::readCalibration(path, format);
    case CameraFormat::Gltf:
        throw Error("camera file '" + path + "': glTF cameras are read with the scene (camera_sources.h)");
    }
    throw Error("camera file '" + path + "': unknown format");
}

std::size_t CameraSet::find(const std::string& frame) const
{
    const std::string what = toString(format) + " camera file '" + path + "'";
    auto some = [&] {
        std::string out;
        for (std::size_t i = 0; i < cameras.size() && i < 4; ++i) out += (i ? ", '" : "'") + cameras[i].name + "'";
        return out + (cameras.size() > 4 ? ", ..." : "");
    };
    if (cameras.empty()) throw Error(what + " holds no camera");
    std::set<std::size_t> matches;
    if (frame.empty() && defaultCamera && *defaultCamera < cameras.size()) {
        matches.insert(*defaultCamera);
    } else if (frame.empty()) {
        if (cameras.size() != 1)
            throw Error(what + " holds " + std::to_string(cameras.size()) + " cameras (" + some() +
                        "): name one as FILE#FRAME, FRAME an index (0.." + std::to_string(cameras.size() - 1) +
                        "), an image name or a file path or stem");
        matches.insert(0);
    } else {
        const std::string wanted = withoutDotSlash(frame);
        for (std::size_t i = 0; i < cameras.size(); ++i) {
            if (withoutDotSlash(cameras[i].name) == wanted) matches.insert(i);
            for (const std::string& alias : cameras[i].aliases)
                if (alias == wanted) matches.insert(i);
        }
        if (isDigits(frame)) {
            std::size_t index = 0;
            const auto [end, error] = std::from_chars(frame.data(), frame.data() + frame.size(), index);
            if (error == std::errc() && end == frame.data() + frame.size() && index < cameras.size()) matches.insert(index);
        }
        if (matches.empty())
            throw Error(what + " has no frame '" + frame + "': it holds " + std::to_string(cameras.size()) +
                        " cameras (indices 0.." + std::to_string(cameras.size() - 1) + "; " + some() + ")");
        if (matches.size() > 1) {
            std::string listed;
            for (std::size_t i : matches)
                listed += (listed.empty() ? "" : ", ") + std::to_string(i) + " ('" + cameras[i].name + "')";
            throw Error(what + ": frame '" + frame + "' names several cameras: " + listed +
                        "; name one by its full image name or path");
        }
    }
    const std::size_t index = *matches.begin();
    if (!cameras[index].refusal.empty()) throw Error(cameras[index].refusal);
    return index;
}

namespace importers {

bool parseFiniteNumber(std::string_view text, double& value)
{
    if (!text.empty() && text.front() == '+') text.remove_prefix(1);
    if (text.empty()) return false;
    const char first = text.front() == '-' ? (text.size() > 1 ? text[1] : '\0') : text.front();
    if (!(std::isdigit(static_cast<unsigned char>(first)) || first == '.')) return false;  // no inf, nan
    for (char c : text)
        if (c == 'x' || c == 'X' || c == 'p' || c == 'P') return false;  // no hex floats
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    return error == std::errc() && end == text.data() + text.size() && std::isfinite(value);
}

std::string pathBeside(const std::string& file, const std::string& relative)
{
    if (relative.empty() || relative.front() == '/') return relative;
    const std::size_t slash = file.find_last_of('/');
    return slash == std::string::npos ? relative : file.substr(0, slash + 1) + relative;
}

std::vector<std::string> pathAliases(const std::string& path)
{
    std::vector<std::string> out;
    const std::string clean = withoutDotSlash(path);
    out.push_back(clean);
    const std::size_t slash = clean.find_last_of('/');
    const std::string name = slash == std::string::npos ? clean : clean.substr(slash + 1);
    if (name != clean) out.push_back(name);
    const std::size_t dot = name.find_last_of('.');
    if (dot != std::string::npos && dot > 0) out.push_back(name.substr(0, dot));
    return out;
}

std::string distortionRefusal(const std::string& where, const std::string& model,
                              const std::vector<std::pair<std::string, double>>& coefficients)
{
    std::string listed;
    bool any = false;
    for (const auto& [name, value] : coefficients) {
        listed += (listed.empty() ? "" : ", ") + name + " = " + formatNumber(value);
        any = any || value != 0;
    }
    if (!any) return "";
    return where + ": camera model " + model + " has lens distortion (" + listed +
           "): zcheck checks linear projections; undistort the depth map and give its pinhole camera";
}

}  // namespace importers

}  // namespace zcheck
