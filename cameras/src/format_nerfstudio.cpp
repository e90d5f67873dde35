// nerfstudio and instant-ngp transforms.json (docs.nerf.studio "Data conventions";
// instant-ngp's nerf_loader), as those projects read them.
//
//   pose    camera-to-world: each frame's transform_matrix, 4x4 (or 3x4) rows
//   axes    OpenGL: x right, y up, z back (the camera looks down −z)
//   pixels  the image's top-left corner is (0, 0): rays pass through index + 0.5, so a
//           centred camera has cx = w/2 (nerfstudio's Cameras, instant-ngp's loader)
//   units   the poses' own; a 16-bit depth PNG holds millimetres by nerfstudio's default
//           (depth_unit_scale_factor 1e-3)
//
// Intrinsics are read per frame, each key falling back to the top level: fl_x, fl_y (pixels),
// else instant-ngp's x_fov, y_fov (degrees) or camera_angle_x, camera_angle_y (radians, over
// the width or height), a missing axis taking the other's focal length (square pixels, as
// instant-ngp does); cx, cy (pixels; default w/2, h/2); w, h (integral numbers, "640.0" too;
// when absent, as in the NeRF-synthetic files, the size is the depth map's and the
// field-of-view keys are resolved against it when the frame is used). camera_model
// SIMPLE_PINHOLE, PINHOLE, or a distortion model (SIMPLE_RADIAL, RADIAL, OPENCV) whose k1..k4,
// p1, p2 (or distortion_params) are all zero; a fisheye or spherical model, or distortion, is
// the frame's refusal. depth_file_path (nerfstudio) or depth_path (instant-ngp) name the
// frame's depth map relative to the file. applied_transform (nerfstudio's transform from the
// data's original coordinates to these poses') and applied_scale are noted: the mesh must be
// in the poses' coordinates.
#include "formats.h"

#include "zcheck/detail/json.h"
#include "zcheck/camera.h"
#include "zcheck/error.h"
#include "zcheck/input_file.h"
#include "zcheck/pose.h"

#include <cmath>
#include <optional>

namespace zcheck::formats {

const CameraFormat& nerfstudioFormat();

namespace {

using nlohmann::json;

class TransformsReader {
public:
    TransformsReader(std::string_view bytes, const std::string& path) : path_(path)
    {
        root_ = parseJsonStrictly(std::string(bytes), source());
        if (!root_.is_object()) fail("the document must be a JSON object");
        const json* frames = find(root_, "frames");
        if (!frames || !frames->is_array()) fail("'frames' must be an array of frames");
        frames_ = frames;
    }

    CameraSet read()
    {
        CameraSet set;
        set.path = path_;
        const std::vector<std::string> notes = documentNotes();
        if (const json* integer = find(root_, "integer_depth_scale")) {
            if (!integer->is_number() || !(integer->get<double>() > 0) || !std::isfinite(integer->get<double>()))
                fail("'integer_depth_scale' must be a positive number");
            set.depthScale = 1 / integer->get<double>();
            set.depthScaleNote = "depth = stored value x " + formatNumber(integer->get<double>()) +
                                 " (the file's integer_depth_scale, instant-ngp)";
        } else {
            set.depthScale = 1000;
            set.depthScaleNote = "depth files hold millimetres, nerfstudio's default (depth_unit_scale_factor 1e-3): "
                                 "scale 1000; --scale replaces it";
        }
        for (std::size_t i = 0; i < frames_->size(); ++i) {
            const json& frame = (*frames_)[i];
            const std::string where = "frames[" + std::to_string(i) + "]";
            if (!frame.is_object()) fail("'" + where + "' must be an object");
            ImportedCamera camera = readFrame(frame, where);
            camera.spec.notes.insert(camera.spec.notes.end(), notes.begin(), notes.end());
            if (camera.name.empty()) camera.name = std::to_string(i);
            set.cameras.push_back(std::move(camera));
        }
        return set;
    }

private:
    std::string source() const { return "transforms file '" + path_ + "'"; }
    [[noreturn]] void fail(const std::string& why) const { throw Error(source() + ": " + why); }

    static const json* find(const json& object, const char* key)
    {
        const auto it = object.find(key);
        return it == object.end() || it->is_null() ? nullptr : &*it;
    }
    // The frame's value of `key`, else the top level's.
    const json* lookup(const json& frame, const char* key) const
    {
        const json* value = find(frame, key);
        return value ? value : find(root_, key);
    }
    std::string keyName(const json& frame, const char* key, const std::string& where) const
    {
        return find(frame, key) ? where + "." + key : std::string(key);
    }
    double number(const json& frame, const char* key, const std::string& where) const
    {
        const json* value = lookup(frame, key);
        if (!value->is_number() || !std::isfinite(value->get<double>()))
            fail("'" + keyName(frame, key, where) + "' must be a finite number");
        return value->get<double>();
    }
    std::optional<int> size(const json& frame, const char* key, const std::string& where) const
    {
        if (!lookup(frame, key)) return std::nullopt;
        const double value = number(frame, key, where);
        if (!Camera::isImageSide(value))
            fail("'" + keyName(frame, key, where) + "' must be a whole number of pixels in 1.." + std::to_string(Camera::kMaxImageSide) + ", got " +
                 formatNumber(value));
        return int(value);
    }

    std::vector<std::string> documentNotes() const
    {
        std::vector<std::string> notes;
        if (const json* applied = find(root_, "applied_transform")) {
            bool identity = applied->is_array() && applied->size() >= 3;
            for (std::size_t r = 0; identity && r < 3; ++r) {
                const json& row = (*applied)[r];
                identity = row.is_array() && row.size() == 4;
                for (std::size_t c = 0; identity && c < 4; ++c)
                    identity = row[c].is_number() && row[c].get<double>() == (r == c ? 1.0 : 0.0);
            }
            if (!identity)
                notes.push_back("transforms file '" + path_ +
                                "' has an applied_transform: its poses are in nerfstudio's transformed coordinates, "
                                "and the mesh must be in them too");
        }
        if (const json* scale = find(root_, "applied_scale"); scale && !(scale->is_number() && scale->get<double>() == 1.0))
            notes.push_back("transforms file '" + path_ + "' has an applied_scale: the mesh must be in the poses' scale");
        return notes;
    }

    double checkedAngle(double radians, const std::string& key) const
    {
        if (!(radians > 0 && radians < M_PI)) fail("'" + key + "' must be a field of view in (0, 180) degrees");
        return radians;
    }

    std::string refusalOf(const json& frame, const std::string& where) const
    {
        const json* model = lookup(frame, "camera_model");
        std::string name = "PINHOLE";
        if (model) {
            if (!model->is_string()) fail("'camera_model' must be a string");
            name = model->get<std::string>();
        }
        const bool linear = name == "PINHOLE" || name == "SIMPLE_PINHOLE" || name == "SIMPLE_RADIAL" || name == "RADIAL" ||
                            name == "OPENCV";
        if (!linear)
            return source() + " " + where + ": camera_model " + name +
                   " is not a pinhole (a fisheye or spherical projection): zcheck checks linear projections";
        std::vector<std::pair<std::string, double>> coefficients;
        for (const char* key : {"k1", "k2", "k3", "k4", "p1", "p2"})
            if (lookup(frame, key)) coefficients.emplace_back(key, number(frame, key, where));
        if (const json* list = lookup(frame, "distortion_params")) {
            if (!list->is_array()) fail("'distortion_params' must be an array of numbers");
            for (std::size_t k = 0; k < list->size(); ++k) {
                if (!(*list)[k].is_number()) fail("'distortion_params' must be an array of numbers");
                coefficients.emplace_back("distortion_params[" + std::to_string(k) + "]", (*list)[k].get<double>());
            }
        }
        return distortionRefusal(source() + " " + where, name, coefficients);
    }

    glm::dmat4 transformMatrix(const json& frame, const std::string& where) const
    {
        const json* m = find(frame, "transform_matrix");
        const std::string key = where + ".transform_matrix";
        if (!m) fail("'" + key + "' is missing (the frame's camera-to-world pose)");
        if (!m->is_array() || (m->size() != 4 && m->size() != 3))
            fail("'" + key + "' must be 4 rows (or 3) of 4 numbers");
        glm::dmat4 worldFromCam(1.0);
        for (std::size_t r = 0; r < m->size(); ++r) {
            const json& row = (*m)[r];
            if (!row.is_array() || row.size() != 4) fail("'" + key + "' must be 4 rows (or 3) of 4 numbers");
            for (std::size_t c = 0; c < 4; ++c) {
                if (!row[c].is_number() || !std::isfinite(row[c].get<double>()))
                    fail("'" + key + "[" + std::to_string(r) + "][" + std::to_string(c) + "]' must be a finite number");
                worldFromCam[int(c)][int(r)] = row[c].get<double>();
            }
        }
        return worldFromCam;
    }

    ImportedCamera readFrame(const json& frame, const std::string& where) const
    {
        ImportedCamera camera;
        if (const json* file = find(frame, "file_path")) {
            if (!file->is_string()) fail("'" + where + ".file_path' must be a string");
            camera.name = file->get<std::string>();
            camera.aliases = pathAliases(camera.name);
        }
        for (const char* key : {"depth_file_path", "depth_path"})
            if (const json* depth = find(frame, key)) {
                if (!depth->is_string()) fail("'" + where + "." + key + "' must be a string");
                camera.depthPath = pathBeside(path_, depth->get<std::string>());
            }

        const std::optional<int> w = size(frame, "w", where), h = size(frame, "h", where);
        if (w.has_value() != h.has_value()) fail("'" + where + "': give both w and h, or neither");
        camera.hasImageSize = w.has_value();
        // The intrinsics as given, resolved over an image size: the file's, or (NeRF-synthetic
        // files give none) the depth map's when the frame is used.
        struct Given {
            std::optional<double> fx, fy, angleX, angleY, cx, cy;
        } given;
        auto angle = [&](const char* degrees, const char* radians) -> std::optional<double> {
            if (lookup(frame, degrees)) return checkedAngle(number(frame, degrees, where) * M_PI / 180, keyName(frame, degrees, where));
            if (lookup(frame, radians)) return checkedAngle(number(frame, radians, where), keyName(frame, radians, where));
            return std::nullopt;
        };
        if (lookup(frame, "fl_x")) given.fx = number(frame, "fl_x", where);
        if (lookup(frame, "fl_y")) given.fy = number(frame, "fl_y", where);
        if (!given.fx) given.angleX = angle("x_fov", "camera_angle_x");
        if (!given.fy) given.angleY = angle("y_fov", "camera_angle_y");
        if (lookup(frame, "cx")) given.cx = number(frame, "cx", where);
        if (lookup(frame, "cy")) given.cy = number(frame, "cy", where);
        if (!given.fx && !given.fy && !given.angleX && !given.angleY)
            fail("'" + where + "' has no focal length: fl_x/fl_y, x_fov/y_fov or camera_angle_x/camera_angle_y");
        if (!camera.hasImageSize && (given.fx || given.fy) && (!given.cx || !given.cy))
            fail("'" + where + "' gives focal lengths in pixels but no image size (w, h) and no principal point (cx, cy)");
        const auto projectionFor = [given](int width, int height) {
            auto over = [](std::optional<double> focal, std::optional<double> angle, int extent) -> std::optional<double> {
                if (focal) return focal;
                if (angle) return 0.5 * extent / std::tan(0.5 * *angle);
                return std::nullopt;
            };
            const std::optional<double> fx = over(given.fx, given.angleX, width), fy = over(given.fy, given.angleY, height);
            PinholeIntrinsics k;
            k.fx = fx ? *fx : *fy, k.fy = fy ? *fy : *fx;  // one axis given: square pixels, as instant-ngp reads it
            k.cx = given.cx.value_or(width / 2.0), k.cy = given.cy.value_or(height / 2.0);
            k.pixelCenter = 0.5;
            return k.projection(kPlaceholderNear, kPlaceholderFar, "intrinsics");
        };
        const int width = w.value_or(kPlaceholderWidth), height = h.value_or(kPlaceholderHeight);
        if (!camera.hasImageSize) camera.projectionForSize = projectionFor;

        const Convention opengl = Convention::preset("opengl");
        CameraSpec& spec = camera.spec;
        spec.convention = opengl;
        spec.width = width, spec.height = height;
        try {
            spec.projection = projectionFor(width, height);
            spec.view = viewFromPose(transformMatrix(frame, where), PoseDirection::WorldFromCamera, opengl, opengl,
                                     where + ".transform_matrix");
            Camera validated(spec);
        } catch (const Error& e) {
            const std::string what = e.what();
            throw Error(what.rfind(source(), 0) == 0 ? what : source() + " " + where + ": " + what);
        }
        camera.refusal = refusalOf(frame, where);
        return camera;
    }

    std::string path_;
    json root_;
    const json* frames_ = nullptr;
};

// transforms.json: fl_x, fl_y, cx, cy, w, h and one frame whose transform_matrix is
// camera-to-world in OpenGL axes.
std::vector<CameraFileText> writeTransformsJson(const Camera& camera, const std::string& name)
{
    const PinholeIntrinsics k = pinholeIntrinsicsOf(camera, 0.5);
    const glm::dmat4 worldFromCam = rigidInverse(camFromWorldIn(camera, Convention::preset("opengl")));
    json rows = json::array();
    for (int r = 0; r < 4; ++r)
        rows.push_back(json::array({worldFromCam[0][r], worldFromCam[1][r], worldFromCam[2][r], worldFromCam[3][r]}));
    const json document = {
        {"camera_model", "PINHOLE"},
        {"fl_x", k.fx}, {"fl_y", k.fy}, {"cx", k.cx}, {"cy", k.cy},
        {"w", camera.width()}, {"h", camera.height()},
        {"frames", json::array({{{"file_path", name}, {"transform_matrix", rows}}})},
    };
    return {{"transforms.json", prettyJson(document) + "\n"}};
}

CameraSet readTransformsJson(std::string_view bytes, const std::string& path) { return TransformsReader(bytes, path).read(); }

bool detectsTransformsJson(const CameraFileHead& file) { return file.looksLikeJson() && file.has("\"frames\""); }

}  // namespace

const CameraFormat& nerfstudioFormat()
{
    static const CameraFormat row = [] {
        CameraFormat f;
        f.name = "nerfstudio";
        f.aliases = {"instant-ngp"};
        f.title = "transforms.json";
        f.extensions = {".json"};
        f.files = "nerfstudio's or instant-ngp's JSON with \"frames\", each a transform_matrix";
        f.example = "transforms.json#frame_003";
        f.priority = 20;
        f.detects = detectsTransformsJson;
        f.parse = readTransformsJson;
        f.write = writeTransformsJson;
        f.datasetSource = true;
        f.namesDepthMaps = true;
        return f;
    }();
    return row;
}

}  // namespace zcheck::formats
