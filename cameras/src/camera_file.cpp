#include "zcheck/camera_file.h"

#include "formats.h"
#include "zcheck/detail/camera_json.h"
#include "zcheck/detail/depth_map_json.h"

#include "zcheck/error.h"
#include "zcheck/input_file.h"
#include "zcheck/pose.h"

#include <algorithm>
#include <cctype>
#include <cmath>
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
    [[noreturn]] void failWith(const std::string& message) const { throw Error(source_ + ": " + message); }
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

// 16 numbers as a column-vector matrix (p' = M·p). "layout" says how the list is ordered
// (row-major: row by row as written on paper; column-major: as OpenGL/GLM store it);
// "vectors" says which side the engine multiplies on (row vectors, p' = p·M, as Direct3D
// writes it, is the transpose).
glm::dmat4 readMatrix(ObjectReader& object, const std::string& key)
{
    const std::vector<double> v = object.numbers(key, 16);
    const std::string layout = object.string("layout", "");
    const std::string vectors = object.string("vectors", "");
    if (layout != "row-major" && layout != "column-major")
        object.failKey("layout", "must be \"row-major\" or \"column-major\" (how the 16 numbers of '" + key + "' are ordered)");
    const std::optional<MatrixVectors> side = matrixVectorsFromName(vectors);
    if (!side) object.failKey("vectors", std::string("must be ") + kMatrixVectorsNames);
    double rows[4][4];
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) rows[r][c] = layout == "row-major" ? v[std::size_t(4 * r + c)] : v[std::size_t(4 * c + r)];
    return matrixForVectors(matrixFromRows(rows), *side);
}

// "far": a number, or "inf" for an infinite far plane.
double readFar(ObjectReader& projection)
{
    if (projection.has("far") && projection.at("far").is_string()) {
        if (projection.string("far", "") != "inf") projection.failKey("far", "must be a number or \"inf\"");
        return INFINITY;
    }
    return projection.number("far");
}

// The "lens" object beside the projection: "model" and the model's parameters by name (lens.h).
// fx, fy, cx, cy come from a pinhole projection when the model has them (OpenCV's K beside its
// distortion coefficients); a projection without a type gives only near and far, and the lens
// every parameter. Parameters past the model's required ones default to 0.
LensSpec readLens(ObjectReader lens, const Projection& pinhole, bool fromPinhole)
{
    LensSpec spec;
    spec.model = lens.string("model", "");
    const LensModelInfo* info = lensModelNamed(spec.model);
    if (!info) lens.failKey("model", spec.model.empty() ? "is missing (" + lensModelNames() + ")"
                                                         : "must be one of " + lensModelNames() + ", got '" + spec.model + "'");
    const double fromProjection[4] = {pinhole.fx, pinhole.fy, pinhole.cx, pinhole.cy};
    const bool hasK = info->startsWithK();
    if (fromPinhole && !hasK)
        lens.failKey("model", "'" + spec.model + "' does not take a pinhole's fx, fy, cx, cy: give the projection only "
                              "near and far, and every parameter in the lens");
    for (std::size_t i = 0; i < info->params.size(); ++i) {
        const std::string name = info->params[i];
        if (fromPinhole && i < 4) {
            if (lens.has(name)) lens.failKey(name, "is the pinhole projection's: give it there only");
            spec.params.push_back(fromProjection[i]);
        } else if (lens.has(name) || int(i) < info->required) {
            spec.params.push_back(lens.number(name));
        } else {
            spec.params.push_back(0.0);
        }
    }
    lens.finish();
    return spec;
}

Projection readProjection(ObjectReader projection, const json* lens, const std::string& source)
{
    Projection p;
    if (lens && !projection.has("type")) {  // near and far only: the lens holds the rest
        p.type = ProjectionType::NonLinear;
        p.lens = readLens(ObjectReader(*lens, "lens", source), p, false);
        p.near = projection.number("near");
        p.far = readFar(projection);
        projection.finish();
        return p;
    }
    const std::string type = projection.string("type", "");
    const std::string types = "perspective, frustum, orthographic, oblique, pinhole, lens or matrix";
    if (type.empty()) projection.failKey("type", "is missing (" + types + ")");
    auto box = [&] {
        p.left = projection.number("left");
        p.right = projection.number("right");
        p.bottom = projection.number("bottom");
        p.top = projection.number("top");
    };
    if (type == "perspective") {
        p.type = ProjectionType::Perspective;
        p.fovyDeg = projection.number("fovy_deg");
        p.aspect = projection.number("aspect", 0.0);
        if (projection.has("aspect") && !(p.aspect > 0)) projection.failKey("aspect", "must be > 0");
    } else if (type == "frustum" || type == "orthographic") {
        p.type = type == "frustum" ? ProjectionType::Frustum : ProjectionType::Orthographic;
        box();
    } else if (type == "oblique") {
        p.type = ProjectionType::Oblique;
        box();
        p.angleDeg = projection.number("angle_deg");
        p.foreshortening = projection.number("foreshortening");
    } else if (type == "pinhole") {
        p.type = ProjectionType::Pinhole;
        p.fx = projection.number("fx");
        p.fy = projection.number("fy");
        p.cx = projection.number("cx");
        p.cy = projection.number("cy");
    } else if (type == "lens") {
        p.type = ProjectionType::Lens;
        p.focalMm = projection.number("focal_mm");
        p.sensorWidthMm = projection.number("sensor_width_mm", 36.0);
    } else if (type == "matrix") {
        p.type = ProjectionType::Matrix;
        p.clipFromEye = readMatrix(projection, "clip_from_eye");
        projection.finish();
        return p;
    } else {
        projection.failKey("type", "must be " + types + ", got '" + type + "'");
    }
    p.near = projection.number("near");
    p.far = readFar(projection);
    projection.finish();
    if (lens) {
        if (p.type != ProjectionType::Pinhole)
            throw Error(source + ": 'lens' goes with a pinhole projection (fx, fy, cx, cy) or one of near and far "
                                 "only, not with a " + type + " projection");
        p.lens = readLens(ObjectReader(*lens, "lens", source), p, true);
        p.type = ProjectionType::NonLinear;
    }
    return p;
}

View readView(ObjectReader view, const Convention& convention)
{
    View v;
    if (view.has("eye_from_world") || view.has("world_from_eye")) {
        if (view.has("eye_from_world") && view.has("world_from_eye"))
            view.fail("takes one of 'eye_from_world' and 'world_from_eye', not both");
        const bool eyeFromWorld = view.has("eye_from_world");
        const std::string key = eyeFromWorld ? "eye_from_world" : "world_from_eye";
        const glm::dmat4 m = readMatrix(view, key);
        // The pose rule (pose.h): checked, re-orthonormalised within the bound, inverted rigidly.
        try {
            v = viewFromPose(m, eyeFromWorld ? PoseDirection::CameraFromWorld : PoseDirection::WorldFromCamera,
                             convention, convention, "view." + key);
        } catch (const Error& e) {
            view.failWith(e.what());
        }
    } else if (view.has("axonometric")) {
        const std::string kind = view.string("axonometric", "");
        const glm::dvec3 target = view.vec3("target");
        const double distance = view.number("distance");
        double azimuth = 45.0, elevation = glm::degrees(std::atan(1.0 / std::sqrt(2.0)));  // isometric
        if (kind == "dimetric") {
            elevation = view.number("elevation_deg", 30.0);
        } else if (kind == "trimetric") {
            azimuth = view.number("azimuth_deg");
            elevation = view.number("elevation_deg");
        } else if (kind != "isometric") {
            view.failKey("axonometric", "must be isometric, dimetric or trimetric, got '" + kind + "'");
        }
        try {
            v = View::axonometricView(kind, target, distance, azimuth, elevation);
        } catch (const Error& e) {
            view.fail(e.what());
        }
    } else {
        v.eye = view.vec3("eye");
        v.target = view.vec3("target");
        v.up = view.has("up") ? view.vec3("up") : glm::dvec3(0, 1, 0);
    }
    view.finish();
    return v;
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
    const json* lens = root.has("lens") ? &root.at("lens") : nullptr;
    spec.projection = readProjection(root.child("projection"), lens, source);
    spec.view = readView(root.child("view"), spec.convention);
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

namespace {

// A camera file's text, or an export sidecar's, as the camera; `path` names it in messages.
CameraSpec cameraSpecFromFileText(std::string_view text, const std::string& path)
{
    const json document = parseJsonStrictly(std::string(text), "camera file '" + path + "'");
    if (isExportSidecar(document)) return cameraSpecFromJson(document["camera"], "sidecar '" + path + "' camera");
    return cameraSpecFromJson(document, "camera file '" + path + "'");
}

}  // namespace

CameraSpec readCameraFile(const std::string& path) { return cameraSpecFromFileText(readInputFile(path, kCameraInput), path); }

namespace {
json matrixJson(const glm::dmat4& m)
{
    json rows = json::array();
    auto clean = [](double v) { return v == 0.0 ? 0.0 : v; };  // no "-0.0" in print
    for (int r = 0; r < 4; ++r)
        rows.push_back(json::array({clean(m[0][r]), clean(m[1][r]), clean(m[2][r]), clean(m[3][r])}));
    return rows;
}
json flatRowMajor(const glm::dmat4& m)
{
    json numbers = json::array();
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) numbers.push_back(m[c][r]);
    return numbers;
}
}  // namespace

json toJson(const CameraSpec& spec)
{
    const Projection& p = spec.projection;
    json projection;
    json lens;
    projection["type"] = toString(p.type);
    switch (p.type) {
    case ProjectionType::NonLinear: {
        // K in a pinhole projection where the model has it, the rest in "lens" (readLens).
        const LensModelInfo& info = *lensModelNamed(p.lens.model);
        const bool hasK = info.startsWithK();
        lens["model"] = p.lens.model;
        if (hasK)
            projection["type"] = "pinhole", projection["fx"] = p.lens.params[0], projection["fy"] = p.lens.params[1],
            projection["cx"] = p.lens.params[2], projection["cy"] = p.lens.params[3];
        else
            projection.erase("type");
        // Every parameter of the model; those a shorter spec leaves out are 0 (lens.h).
        for (std::size_t i = hasK ? 4 : 0; i < info.params.size(); ++i)
            lens[info.params[i]] = i < p.lens.params.size() ? p.lens.params[i] : 0.0;
        break;
    }
    case ProjectionType::Perspective:
        projection["fovy_deg"] = p.fovyDeg;
        if (p.aspect > 0) projection["aspect"] = p.aspect;
        break;
    case ProjectionType::Pinhole:
        projection["fx"] = p.fx, projection["fy"] = p.fy, projection["cx"] = p.cx, projection["cy"] = p.cy;
        break;
    case ProjectionType::Lens:
        projection["focal_mm"] = p.focalMm, projection["sensor_width_mm"] = p.sensorWidthMm;
        break;
    case ProjectionType::Matrix:
        projection["clip_from_eye"] = flatRowMajor(p.clipFromEye);
        projection["layout"] = "row-major";
        projection["vectors"] = "column";
        break;
    case ProjectionType::Oblique:
        projection["angle_deg"] = p.angleDeg, projection["foreshortening"] = p.foreshortening;
        [[fallthrough]];
    default:
        projection["left"] = p.left, projection["right"] = p.right;
        projection["bottom"] = p.bottom, projection["top"] = p.top;
    }
    if (p.type != ProjectionType::Matrix) {
        projection["near"] = p.near;
        projection["far"] = std::isinf(p.far) ? json("inf") : json(p.far);
    }
    auto array3 = [](const glm::dvec3& v) { return json::array({v.x, v.y, v.z}); };
    json view;
    const View& v = spec.view;
    if (v.hasMatrix) {
        view = {{"eye_from_world", flatRowMajor(v.eyeFromWorld)}, {"layout", "row-major"}, {"vectors", "column"}};
    } else if (!v.axonometric.empty()) {
        view = {{"axonometric", v.axonometric}, {"target", array3(v.target)}, {"distance", v.distance}};
        if (v.axonometric != "isometric") view["elevation_deg"] = v.elevationDeg;
        if (v.axonometric == "trimetric") view["azimuth_deg"] = v.azimuthDeg;
    } else {
        view = {{"eye", array3(v.eye)}, {"target", array3(v.target)}, {"up", array3(v.up)}};
    }
    json out{
        {"convention", spec.convention.name},
        {"image", {{"width", spec.width}, {"height", spec.height}}},
        {"projection", projection},
        {"view", view},
        {"depth",
         {{"format", toString(spec.depth.format)},
          {"reversed", spec.depth.reversed},
          {"range", json::array({spec.depth.rangeMin, spec.depth.rangeMax})}}},
    };
    if (p.type == ProjectionType::NonLinear) out["lens"] = lens;
    return out;
}

json matricesJson(const Camera& camera)
{
    if (const LensModel* lens = camera.lens())  // no projection matrix: the view, and what projects instead
        return json{
            {"vectors", "column (p' = M·p), rows as printed"},
            {"eye_from_world", matrixJson(camera.eyeFromWorld)},
            {"world_from_eye", matrixJson(camera.worldFromEye)},
            {"projection", "lens model " + lens->spec().model +
                               ": no projection matrix; the camera's 'lens' maps directions to pixels (near and far are "
                               "distances along the rays)"},
            {"near", camera.nearDistance()},
            {"far", camera.farIsInfinite() ? json("inf") : json(camera.farDistance())},
        };
    json out = {
        {"vectors", "column (p' = M·p), rows as printed"},
        {"eye_from_world", matrixJson(camera.eyeFromWorld)},
        {"world_from_eye", matrixJson(camera.worldFromEye)},
        {"clip_from_eye", matrixJson(camera.clipFromEye)},
        {"eye_from_clip", matrixJson(camera.eyeFromClip)},
        {"clip_from_world", matrixJson(camera.clipFromWorld)},
        {"window_from_ndc", matrixJson(camera.windowFromNdc)},
        {"ndc_from_window", matrixJson(camera.ndcFromWindow)},
        {"near", camera.nearDistance()},
        {"far", camera.farIsInfinite() ? json("inf") : json(camera.farDistance())},
    };
    const bool rows = camera.convention().rowVectors;
    auto native = [&](const glm::dmat4& m) {
        return matrixJson(matrixForVectors(m, rows ? MatrixVectors::Row : MatrixVectors::Column));
    };
    out["native"] = {
        {"convention", camera.convention().name},
        {"vectors", rows ? "row (p' = p·M): the transposes of the above" : "column (p' = M·p)"},
        {"eye_from_world", native(camera.eyeFromWorld)},
        {"clip_from_eye", native(camera.clipFromEye)},
        {"window_from_ndc", native(camera.windowFromNdc)},
    };
    return out;
}

CameraSpec cameraSpecFromJsonText(const std::string& text, const std::string& source)
{
    return cameraSpecFromJson(parseJsonStrictly(text, source), source);
}

std::string cameraJsonText(const CameraSpec& spec) { return prettyJson(toJson(spec)); }
std::string matricesJsonText(const Camera& camera) { return prettyJson(matricesJson(camera)); }

namespace formats {

namespace {

CameraSet readZcheckCamera(std::string_view bytes, const std::string& path)
{
    CameraSet set;
    ImportedCamera camera;
    camera.spec = cameraSpecFromFileText(bytes, path);
    camera.hasClipPlanes = true;
    const std::size_t slash = path.find_last_of('/');
    camera.name = slash == std::string::npos ? path : path.substr(slash + 1);
    set.cameras.push_back(camera);
    return set;
}

std::vector<CameraFileText> writeZcheckCamera(const Camera& camera, const std::string&)
{
    return {{"camera.json", cameraJsonText(camera.spec()) + "\n"}};
}

// Any other JSON is read as a zcheck camera, whose reader names what is wrong with it.
bool detectsZcheckCamera(const CameraFileHead& file) { return file.looksLikeJson(); }

}  // namespace

const CameraFormat& zcheckFormat()
{
    static const CameraFormat row = [] {
        CameraFormat f;
        f.name = "zcheck";
        f.title = "zcheck camera";
        f.extensions = {".json"};
        f.files = "JSON: a camera file (camera_file.h) or the sidecar `zcheck export` writes";
        f.example = "camera.json";
        f.priority = 90;
        f.detects = detectsZcheckCamera;
        f.parse = readZcheckCamera;
        f.input = kCameraInput;
        f.write = writeZcheckCamera;
        return f;
    }();
    return row;
}

}  // namespace formats

}  // namespace zcheck
