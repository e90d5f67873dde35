#include "zcheck/camera_file.h"

#include "zcheck/error.h"

#include <algorithm>
#include <fstream>
#include <sstream>

namespace zcheck {

namespace {

using nlohmann::json;

// Reads one JSON object strictly: every key must be consumed, every value of the right type.
class ObjectReader {
public:
    ObjectReader(const json& object, std::string path, std::string source)
        : object_(object), path_(std::move(path)), source_(std::move(source))
    {
        if (!object_.is_object()) fail(path_.empty() ? "the document must be a JSON object" : "must be an object");
    }

    bool has(const std::string& key) const { return object_.contains(key); }

    const json& at(const std::string& key)
    {
        consumed_.push_back(key);
        if (!object_.contains(key)) failKey(key, "is missing");
        return object_.at(key);
    }

    double number(const std::string& key)
    {
        const json& value = at(key);
        if (!value.is_number()) failKey(key, "must be a number");
        return value.get<double>();
    }
    double number(const std::string& key, double fallback) { return has(key) ? number(key) : fallback; }

    int integer(const std::string& key, int fallback)
    {
        if (!has(key)) return fallback;
        const json& value = at(key);
        if (!value.is_number_integer()) failKey(key, "must be an integer");
        const auto wide = value.get<long long>();
        if (wide < -(1LL << 30) || wide > (1LL << 30)) failKey(key, "is out of range");
        return static_cast<int>(wide);
    }

    bool boolean(const std::string& key, bool fallback)
    {
        if (!has(key)) return fallback;
        const json& value = at(key);
        if (!value.is_boolean()) failKey(key, "must be true or false");
        return value.get<bool>();
    }

    std::string string(const std::string& key, const std::string& fallback)
    {
        if (!has(key)) return fallback;
        const json& value = at(key);
        if (!value.is_string()) failKey(key, "must be a string");
        return value.get<std::string>();
    }

    std::vector<double> numbers(const std::string& key, std::size_t count)
    {
        const json& value = at(key);
        if (!value.is_array() || value.size() != count)
            failKey(key, "must be an array of " + std::to_string(count) + " numbers");
        std::vector<double> out;
        for (const auto& element : value) {
            if (!element.is_number()) failKey(key, "must be an array of " + std::to_string(count) + " numbers");
            out.push_back(element.get<double>());
        }
        return out;
    }

    glm::dvec3 vec3(const std::string& key)
    {
        const auto v = numbers(key, 3);
        return {v[0], v[1], v[2]};
    }

    ObjectReader child(const std::string& key) { return ObjectReader(at(key), name(key), source_); }

    // Every key present must have been read.
    void finish() const
    {
        for (const auto& item : object_.items())
            if (std::find(consumed_.begin(), consumed_.end(), item.key()) == consumed_.end())
                throw Error(source_ + ": unknown key '" + name(item.key()) + "'");
    }

    [[noreturn]] void failKey(const std::string& key, const std::string& what) const
    {
        throw Error(source_ + ": '" + name(key) + "' " + what);
    }
    [[noreturn]] void fail(const std::string& what) const
    {
        throw Error(source_ + ": " + (path_.empty() ? "" : "'" + path_ + "' ") + what);
    }

private:
    std::string name(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

    const json& object_;
    std::string path_;
    std::string source_;
    std::vector<std::string> consumed_;
};

Projection readProjection(ObjectReader projection)
{
    Projection p;
    const std::string type = projection.string("type", "");
    if (type.empty()) projection.failKey("type", "is missing (perspective, frustum or orthographic)");
    if (type == "perspective") {
        p.type = ProjectionType::Perspective;
        p.fovyDeg = projection.number("fovy_deg");
        p.aspect = projection.number("aspect", 0.0);
        if (projection.has("aspect") && !(p.aspect > 0)) projection.failKey("aspect", "must be > 0");
    } else if (type == "frustum" || type == "orthographic") {
        p.type = type == "frustum" ? ProjectionType::Frustum : ProjectionType::Orthographic;
        p.left = projection.number("left");
        p.right = projection.number("right");
        p.bottom = projection.number("bottom");
        p.top = projection.number("top");
    } else {
        projection.failKey("type", "must be perspective, frustum or orthographic, got '" + type + "'");
    }
    p.near = projection.number("near");
    p.far = projection.number("far");
    projection.finish();
    return p;
}

}  // namespace

CameraSpec cameraSpecFromJson(const json& document, const std::string& source)
{
    ObjectReader root(document, "", source);
    CameraSpec spec;
    const std::string convention = root.string("convention", "opengl");
    try {
        spec.convention = Convention::preset(convention);
    } catch (const Error& e) {
        root.failKey("convention", std::string("is invalid: ") + e.what());
    }
    if (root.has("image")) {
        ObjectReader image = root.child("image");
        spec.width = image.integer("width", 640);
        spec.height = image.integer("height", 480);
        image.finish();
    }
    spec.projection = readProjection(root.child("projection"));
    {
        ObjectReader view = root.child("view");
        spec.view.eye = view.vec3("eye");
        spec.view.target = view.vec3("target");
        spec.view.up = view.has("up") ? view.vec3("up") : glm::dvec3(0, 1, 0);
        view.finish();
    }
    if (root.has("depth")) {
        ObjectReader depth = root.child("depth");
        const std::string format = depth.string("format", "float32");
        try {
            spec.depth.format = depthFormatFromName(format);
        } catch (const Error& e) {
            depth.failKey("format", std::string("is invalid: ") + e.what());
        }
        spec.depth.reversed = depth.boolean("reversed", false);
        if (depth.has("range")) {
            const auto range = depth.numbers("range", 2);
            spec.depth.rangeMin = range[0];
            spec.depth.rangeMax = range[1];
        }
        depth.finish();
    }
    root.finish();
    try {
        Camera validated(spec);
    } catch (const Error& e) {
        throw Error(source + ": " + e.what());
    }
    return spec;
}

CameraSpec readCameraFile(const std::string& path)
{
    std::ifstream in(path);
    if (!in) throw Error("cannot read camera file '" + path + "': no such file or not readable");
    json document;
    try {
        document = json::parse(in);
    } catch (const json::exception& e) {  // syntax errors, and numbers out of range such as 1e400
        std::string what = e.what();
        throw Error("camera file '" + path + "' is not valid JSON: " + what.substr(what.find(']') + 2));
    }
    return cameraSpecFromJson(document, "camera file '" + path + "'");
}

json toJson(const CameraSpec& spec)
{
    json projection;
    projection["type"] = toString(spec.projection.type);
    if (spec.projection.type == ProjectionType::Perspective) {
        projection["fovy_deg"] = spec.projection.fovyDeg;
        if (spec.projection.aspect > 0) projection["aspect"] = spec.projection.aspect;
    } else {
        projection["left"] = spec.projection.left;
        projection["right"] = spec.projection.right;
        projection["bottom"] = spec.projection.bottom;
        projection["top"] = spec.projection.top;
    }
    projection["near"] = spec.projection.near;
    projection["far"] = spec.projection.far;
    auto array3 = [](const glm::dvec3& v) { return json::array({v.x, v.y, v.z}); };
    return json{
        {"convention", spec.convention.name},
        {"image", {{"width", spec.width}, {"height", spec.height}}},
        {"projection", projection},
        {"view", {{"eye", array3(spec.view.eye)}, {"target", array3(spec.view.target)}, {"up", array3(spec.view.up)}}},
        {"depth",
         {{"format", toString(spec.depth.format)},
          {"reversed", spec.depth.reversed},
          {"range", json::array({spec.depth.rangeMin, spec.depth.rangeMax})}}},
    };
}

}  // namespace zcheck
