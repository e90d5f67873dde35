#include "zcheck/camera_import.h"

#include "formats.h"
#include "zcheck/pose.h"
#include "zcheck/error.h"
#include "zcheck/input_file.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <set>
#include <cstdio>
#include <sys/stat.h>

namespace zcheck {

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

}  // namespace

std::pair<std::string, std::string> splitCameraReference(const std::string& reference)
{
    const std::size_t hash = reference.rfind('#');
    if (hash == std::string::npos || exists(reference)) return {reference, ""};
    return {reference.substr(0, hash), reference.substr(hash + 1)};
}

std::size_t CameraSet::find(const std::string& frame) const
{
    const std::string what = format + " camera file '" + path + "'";
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

namespace formats {

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

std::string exactNumber(double value)
{
    char text[40];
    std::snprintf(text, sizeof text, "%.17g", value == 0.0 ? 0.0 : value);
    return text;
}

glm::dmat4 camFromWorldIn(const Camera& camera, const Convention& axes)
{
    return eyeFromEye(axes, camera.convention()) * camera.eyeFromWorld;
}

}  // namespace formats

}  // namespace zcheck
