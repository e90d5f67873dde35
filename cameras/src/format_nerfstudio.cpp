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
// field-of-view keys are resolved against it when the frame is used). depth_file_path
// (nerfstudio) or depth_path (instant-ngp) name the frame's depth map relative to the file.
// applied_transform (nerfstudio's transform from the data's original coordinates to these
// poses') and applied_scale are noted: the mesh must be in the poses' coordinates.
//
// The lens, as each program reads it (sources: nerfstudio 50e0e3c, instant-ngp abe236e):
//
//   nerfstudio  camera_model (CAMERA_MODEL_TO_TYPE in cameras/cameras.py; absent: PERSPECTIVE);
//               distortion from the top level when it gives any of k1, k2, k3, p1, p2,
//               distortion_params, else from the frame (dataparsers/nerfstudio_dataparser.py),
//               distortion_params before the named keys k1, k2, k3, k4, p1, p2 (absent ones 0;
//               camera_utils.get_distortion_params)
//     SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV (PERSPECTIVE): [k1 k2 k3 k4 p1 p2]
//               → brown_conrady (camera_utils._compute_residual_and_jacobian: k4 multiplies r⁸,
//               it is not OpenCV's rational k4); all zero: a pinhole
//     OPENCV_FISHEYE (FISHEYE): the same six undistort θ·(cos φ, sin φ) (cameras.py,
//               _generate_rays_from_coords) → opencv_fisheye [k1..k4], or with p1, p2 ≠ 0
//               thin_prism_fisheye [k1 k2 p1 p2 k3 k4]
//     FISHEYE624: distortion_params [k0..k5 p0 p1 s0..s3] (12) → fisheye624
//               (camera_utils.fisheye624_project)
//     EQUIRECTANGULAR: no distortion; longitude π(x − cx)/fl_x, latitude −π(y − cy)/fl_y in the
//               camera's OpenCV axes, longitude 0 (forward) at x = cx (cameras.py) →
//               equirectangular over the longitudes and latitudes the image spans
//     OMNIDIRECTIONALSTEREO_*, VR180_*, ORTHOPHOTO: refused (their rays do not meet at a point)
//   instant-ngp (src/nerf_loader.cu read_lens, the top level and then the frame's own keys;
//               include/neural-graphics-primitives/common_device.cuh): k1, k2, k3, k4 into
//               places 0..3, then p1, p2 into places 2, 3; a nonzero one turns the lens on:
//               OpenCV [k1 k2 p1 p2] → brown_conrady, or with is_fisheye [k1 k2 k3 k4] →
//               opencv_fisheye; latlong → equirectangular over the whole sphere; its
//               "equirectangular" (equal-area), orthographic and f-theta modes are refused.
//
// Which program reads a frame: camera_model and distortion_params are nerfstudio's keys,
// is_fisheye, latlong, equirectangular, orthographic and ftheta_p0 instant-ngp's; a frame with
// the keys of one is read by it, a frame with both kinds or neither by both, and then their two
// readings must give the same lens, else the frame is refused naming both.
#include "formats.h"

#include "zcheck/detail/json.h"
#include "zcheck/camera.h"
#include "zcheck/error.h"
#include "zcheck/input_file.h"
#include "zcheck/lens.h"
#include "zcheck/pose.h"

#include <cmath>
#include <optional>

namespace zcheck::formats {

const CameraFormat& nerfstudioFormat();

namespace {

using nlohmann::json;

constexpr const char* kPerspectiveModels[] = {"SIMPLE_PINHOLE", "PINHOLE", "SIMPLE_RADIAL", "RADIAL", "OPENCV"};
constexpr const char* kNerfstudioModels =
    "SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV, OPENCV_FISHEYE, EQUIRECTANGULAR, OMNIDIRECTIONALSTEREO_L, "
    "OMNIDIRECTIONALSTEREO_R, VR180_L, VR180_R, ORTHOPHOTO, FISHEYE624";

// A frame's lens as one program reads it.
struct FrameLens {
    enum class Kind { Pinhole, Model, Panorama, Sphere } kind = Kind::Pinhole;
    std::string model;                 // Kind::Model: a lens model (lens.h)
    std::vector<double> coefficients;  // its parameters after fx, fy, cx, cy
    std::string refusal;               // why zcheck has no camera for it ("" for none)
    std::vector<std::string> notes;

    static FrameLens lens(const std::string& model, std::vector<double> coefficients)
    {
        FrameLens out;
        out.kind = Kind::Model, out.model = model, out.coefficients = std::move(coefficients);
        return out;
    }
    static FrameLens refused(const std::string& why)
    {
        FrameLens out;
        out.refusal = why;
        return out;
    }
    bool sameAs(const FrameLens& other) const
    {
        return kind == other.kind && model == other.model && coefficients == other.coefficients &&
               refusal.empty() && other.refusal.empty();
    }
    std::string description() const
    {
        if (!refusal.empty()) return "no camera zcheck reads (" + refusal + ")";
        switch (kind) {
        case Kind::Pinhole: return "a pinhole";
        case Kind::Panorama: return "nerfstudio's EQUIRECTANGULAR panorama";
        case Kind::Sphere: return "an equirectangular panorama of the whole sphere";
        case Kind::Model: break;
        }
        std::string out = "lens model " + model + " (";
        const LensModelInfo* info = lensModelNamed(model);
        for (std::size_t i = 0; i < coefficients.size(); ++i)
            out += std::string(i ? ", " : "") + (info ? info->params[i + 4] : "?") + " = " + formatNumber(coefficients[i]);
        return out + ")";
    }
};

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
    // `key` of `object` (the frame, or the top level), which must be a finite number.
    double numberIn(const json& object, const char* key, const std::string& where) const
    {
        const json* value = find(object, key);
        const std::string name = &object == &root_ ? std::string(key) : where + "." + key;
        if (!value->is_number() || !std::isfinite(value->get<double>())) fail("'" + name + "' must be a finite number");
        return value->get<double>();
    }
    double number(const json& frame, const char* key, const std::string& where) const
    {
        return numberIn(find(frame, key) ? frame : root_, key, where);
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

    // ---- the lens ------------------------------------------------------------------------

    // nerfstudio's distortion for the frame: `count` numbers, distortion_params or the named
    // keys [k1 k2 k3 k4 p1 p2] (nerfstudio_dataparser.py, _generate_dataparser_outputs).
    std::vector<double> nerfstudioDistortion(const json& frame, const std::string& where, std::size_t count,
                                             const std::string& model, FrameLens& lens) const
    {
        bool topLevel = false;
        for (const char* key : {"k1", "k2", "k3", "p1", "p2", "distortion_params"}) topLevel = topLevel || find(root_, key);
        const json& from = topLevel ? root_ : frame;
        const json& unused = topLevel ? frame : root_;
        for (const char* key : {"k1", "k2", "k3", "k4", "p1", "p2"})
            if (find(unused, key) && numberIn(unused, key, where) != 0)
                lens.notes.push_back(source() + " " + where + ": " + (topLevel ? where + "." + key : std::string(key)) +
                                     " is not used: nerfstudio takes every frame's distortion from the top level when it "
                                     "gives any of k1, k2, k3, p1, p2, distortion_params, else each frame's own");
        const std::string listKey = topLevel ? std::string("distortion_params") : where + ".distortion_params";
        if (const json* list = find(from, "distortion_params")) {
            if (!list->is_array()) fail("'" + listKey + "' must be an array of numbers");
            std::vector<double> values;
            for (std::size_t i = 0; i < list->size(); ++i) {
                const json& v = (*list)[i];
                if (!v.is_number() || !std::isfinite(v.get<double>()))
                    fail("'" + listKey + "[" + std::to_string(i) + "]' must be a finite number");
                values.push_back(v.get<double>());
            }
            if (values.size() != count)
                fail("'" + listKey + "' holds " + std::to_string(values.size()) + " numbers; camera_model " + model +
                     " takes " + std::to_string(count) +
                     (count == 12 ? " (k0..k5, p0, p1, s0..s3)" : " (k1, k2, k3, k4, p1, p2)"));
            return values;
        }
        if (count == 12)
            fail("'" + where + "': camera_model FISHEYE624 takes distortion_params, 12 numbers (k0..k5, p0, p1, "
                 "s0..s3), as nerfstudio's dataparser reads it; the frame gives none");
        std::vector<double> values(6, 0.0);
        const char* keys[] = {"k1", "k2", "k3", "k4", "p1", "p2"};
        for (int i = 0; i < 6; ++i)
            if (find(from, keys[i])) values[std::size_t(i)] = numberIn(from, keys[i], where);
        return values;
    }

    FrameLens nerfstudioLens(const json& frame, const std::string& where, const std::string& model) const
    {
        FrameLens lens;
        const std::string at = source() + " " + where + ": camera_model " + model;
        bool perspective = model.empty();
        for (const char* name : kPerspectiveModels) perspective = perspective || model == name;
        if (perspective) {
            const std::vector<double> d = nerfstudioDistortion(frame, where, 6, model.empty() ? "PINHOLE" : model, lens);
            bool any = false;
            for (double v : d) any = any || v != 0;
            if (any) lens.kind = FrameLens::Kind::Model, lens.model = "brown_conrady", lens.coefficients = d;
        } else if (model == "OPENCV_FISHEYE") {
            const std::vector<double> d = nerfstudioDistortion(frame, where, 6, model, lens);
            lens.kind = FrameLens::Kind::Model;
            if (d[4] == 0 && d[5] == 0)
                lens.model = "opencv_fisheye", lens.coefficients = {d[0], d[1], d[2], d[3]};
            else  // the tangential pair on the θ-plane before the radial factor, as nerfstudio undistorts it
                lens.model = "thin_prism_fisheye", lens.coefficients = {d[0], d[1], d[4], d[5], d[2], d[3], 0, 0};
        } else if (model == "FISHEYE624") {
            lens.kind = FrameLens::Kind::Model, lens.model = "fisheye624";
            lens.coefficients = nerfstudioDistortion(frame, where, 12, model, lens);
        } else if (model == "EQUIRECTANGULAR") {
            lens.kind = FrameLens::Kind::Panorama;
            for (const char* key : {"k1", "k2", "k3", "k4", "p1", "p2"})
                if (lookup(frame, key) && number(frame, key, where) != 0)
                    lens.notes.push_back(at + " has no distortion in nerfstudio (cameras.py skips it for "
                                              "EQUIRECTANGULAR): '" + keyName(frame, key, where) + "' is not used");
        } else if (model.rfind("OMNIDIRECTIONALSTEREO_", 0) == 0 || model.rfind("VR180_", 0) == 0) {
            return FrameLens::refused(at + " starts its rays 32 mm beside the camera's centre (a stereo panorama, "
                                           "nerfstudio's cameras.py): zcheck's cameras have one centre of projection");
        } else if (model == "ORTHOPHOTO") {
            return FrameLens::refused(at + " has parallel rays (an orthophoto): zcheck reads nerfstudio's central "
                                           "cameras");
        } else {
            return FrameLens::refused(at + " is not one of nerfstudio's (" + kNerfstudioModels + ")");
        }
        return lens;
    }

    // instant-ngp's read_lens on one object (the top level, then the frame) over `lens`.
    struct NgpLens {
        enum class Mode { Perspective, OpenCV, OpenCVFisheye, FTheta, LatLong, Equirectangular, Orthographic };
        Mode mode = Mode::Perspective;
        double params[4] = {0, 0, 0, 0};
    };
    void ngpReadLens(const json& object, const std::string& where, NgpLens& lens) const
    {
        using Mode = NgpLens::Mode;
        Mode mode = Mode::Perspective;
        bool fisheye = false;
        if (const json* flag = find(object, "is_fisheye")) {
            if (!flag->is_boolean())
                fail("'" + (&object == &root_ ? std::string() : where + ".") + "is_fisheye' must be true or false");
            fisheye = flag->get<bool>();
        }
        const std::pair<const char*, int> places[] = {{"k1", 0}, {"k2", 1}, {"k3", 2}, {"k4", 3}, {"p1", 2}, {"p2", 3}};
        for (const auto& [key, place] : places)
            if (find(object, key)) {
                lens.params[place] = numberIn(object, key, where);
                if (lens.params[place] != 0) mode = fisheye ? Mode::OpenCVFisheye : Mode::OpenCV;
            }
        if (object.contains("ftheta_p0")) mode = Mode::FTheta;
        if (object.contains("latlong")) mode = Mode::LatLong;
        else if (object.contains("equirectangular")) mode = Mode::Equirectangular;
        else if (object.contains("orthographic")) mode = Mode::Orthographic;
        if (mode != Mode::Perspective) lens.mode = mode;
    }

    // What instant-ngp's loader makes of the frame's lens keys.
    FrameLens ngpReading(const json& frame, const std::string& where) const
    {
        using Mode = NgpLens::Mode;
        NgpLens ngp;
        ngpReadLens(root_, where, ngp);
        ngpReadLens(frame, where, ngp);
        const std::string at = source() + " " + where + ": instant-ngp's ";
        const double* q = ngp.params;
        FrameLens read;
        switch (ngp.mode) {
        case Mode::Perspective: break;
        case Mode::OpenCV: read = FrameLens::lens("brown_conrady", {q[0], q[1], 0, 0, q[2], q[3]}); break;
        case Mode::OpenCVFisheye: read = FrameLens::lens("opencv_fisheye", {q[0], q[1], q[2], q[3]}); break;
        case Mode::LatLong: read.kind = FrameLens::Kind::Sphere; return read;
        case Mode::Equirectangular:
            return FrameLens::refused(at + "'equirectangular' lens is a cylindrical equal-area panorama (its height "
                                           "is linear in the sine of latitude; common_device.cuh "
                                           "equirectangular_to_dir): zcheck has no lens model for it");
        case Mode::Orthographic:
            return FrameLens::refused(at + "'orthographic' lens has parallel rays: zcheck reads instant-ngp's "
                                           "central cameras");
        case Mode::FTheta:
            return FrameLens::refused(at + "f-theta lens (ftheta_p0..ftheta_p4): zcheck has no lens model for it");
        }
        return read;
    }

    // instant-ngp's reading, where it is what the keys say.
    FrameLens ngpLens(const json& frame, const std::string& where) const
    {
        const FrameLens read = ngpReading(frame, where);
        if (!read.refusal.empty() || (read.kind != FrameLens::Kind::Pinhole && read.kind != FrameLens::Kind::Model))
            return read;
        // Its loader's reading is taken only where it is what the keys name (each the frame's,
        // else the top level's): k3, k4 radial terms, p1, p2 tangential, is_fisheye a fisheye.
        bool fisheye = false;
        if (const json* flag = lookup(frame, "is_fisheye")) fisheye = flag->get<bool>();
        std::vector<double> named;
        for (const char* key : {"k1", "k2", "k3", "k4", "p1", "p2"})
            named.push_back(lookup(frame, key) ? number(frame, key, where) : 0.0);
        bool any = false;
        for (double v : named) any = any || v != 0;
        FrameLens meant;
        if (fisheye && (named[4] != 0 || named[5] != 0))
            meant = FrameLens::refused("a fisheye with tangential terms p1, p2, which instant-ngp's fisheye has not");
        else if (fisheye)
            meant = FrameLens::lens("opencv_fisheye", {named[0], named[1], named[2], named[3]});
        else if (any)
            meant = FrameLens::lens("brown_conrady", named);
        if (read.sameAs(meant)) return read;
        return FrameLens::refused(
            source() + " " + where + ": instant-ngp's loader (nerf_loader.cu read_lens) reads its lens as " +
            read.description() + ", though its keys name " + meant.description() + ": it puts p1, p2 in the places of k3, k4, turns a lens on only for a nonzero "
            "coefficient, and takes a frame's own coefficients with the frame's own is_fisheye (default false); "
            "give camera_model for nerfstudio's reading, or keys instant-ngp reads as they say");
    }

    FrameLens lensOf(const json& frame, const std::string& where) const
    {
        std::string model;
        if (const json* given = lookup(frame, "camera_model")) {
            if (!given->is_string()) fail("'camera_model' must be a string");
            model = given->get<std::string>();
        }
        const bool nerfstudioKeys = lookup(frame, "camera_model") || lookup(frame, "distortion_params");
        bool ngpKeys = false;
        for (const char* key : {"is_fisheye", "latlong", "equirectangular", "orthographic", "ftheta_p0"})
            ngpKeys = ngpKeys || frame.contains(key) || root_.contains(key);
        const bool byNerfstudio = nerfstudioKeys || !ngpKeys, byNgp = ngpKeys || !nerfstudioKeys;
        if (!byNgp) return nerfstudioLens(frame, where, model);
        if (!byNerfstudio) return ngpLens(frame, where);
        FrameLens nerfstudio = nerfstudioLens(frame, where, model);
        const FrameLens ngp = ngpReading(frame, where);
        if (nerfstudio.sameAs(ngp) || (!nerfstudio.refusal.empty() && !ngp.refusal.empty())) return nerfstudio;
        return FrameLens::refused(
            source() + " " + where + ": nerfstudio and instant-ngp read its lens differently: nerfstudio (camera_model " +
            (model.empty() ? "absent: PERSPECTIVE" : model) + ", k4 an r⁸ term) as " + nerfstudio.description() +
            ", instant-ngp (nerf_loader.cu read_lens: p1, p2 take k3's and k4's places, is_fisheye picks its fisheye, a "
            "lens with every coefficient 0 is a pinhole) as " + ngp.description() +
            "; keep the keys of the program the file is for (camera_model and distortion_params are nerfstudio's, "
            "is_fisheye and latlong instant-ngp's)");
    }

    // nerfstudio's EQUIRECTANGULAR over the image: longitude π(x − cx)/fx, latitude −π(y − cy)/fy
    // (cameras.py, in OpenCV's axes), x and y with pixel centres at +0.5 as zcheck's image.
    static Projection panorama(const PinholeIntrinsics& k, int width, int height)
    {
        k.projection(kPlaceholderNear, kPlaceholderFar, "intrinsics");  // refuses focal lengths ≤ 0
        double lonMin = -180 * k.cx / k.fx, lonMax = 180 * (width - k.cx) / k.fx;
        double latMax = 180 * k.cy / k.fy, latMin = 180 * (k.cy - height) / k.fy;
        constexpr double kRounding = 1e-9;  // degrees: fl_x = w/2 written with a rounded digit
        if (lonMax - lonMin > 360 && lonMax - lonMin <= 360 + kRounding) lonMax = lonMin + 360;
        if (latMax > 90 && latMax <= 90 + kRounding) latMax = 90;
        if (latMin < -90 && latMin >= -90 - kRounding) latMin = -90;
        const std::string given = "camera_model EQUIRECTANGULAR: ";
        if (lonMax - lonMin > 360 || lonMin < -360 || lonMax > 360)
            throw Error(given + "fl_x = " + formatNumber(k.fx) + ", cx = " + formatNumber(k.cx) + " over w = " +
                        std::to_string(width) + " span longitudes " + formatNumber(lonMin) + "° to " +
                        formatNumber(lonMax) + "° (nerfstudio: 180°·(x − cx)/fl_x): a panorama spans at most 360° "
                        "(fl_x ≥ w/2)");
        if (latMax > 90 || latMin < -90)
            throw Error(given + "fl_y = " + formatNumber(k.fy) + ", cy = " + formatNumber(k.cy) + " over h = " +
                        std::to_string(height) + " span latitudes " + formatNumber(latMin) + "° to " +
                        formatNumber(latMax) + "° (nerfstudio: −180°·(y − cy)/fl_y): latitudes end at ±90° (fl_y = h, "
                        "cy = h/2 for the whole sphere)");
        Projection p;
        p.type = ProjectionType::NonLinear;
        p.lens = {"equirectangular", {lonMin, lonMax, latMin, latMax}};
        p.near = kPlaceholderNear, p.far = kPlaceholderFar;
        return p;
    }

    static Projection projectionWith(const FrameLens& lens, const PinholeIntrinsics& k, int width, int height)
    {
        if (!lens.refusal.empty()) return k.projection(kPlaceholderNear, kPlaceholderFar, "intrinsics");
        switch (lens.kind) {
        case FrameLens::Kind::Pinhole: break;
        case FrameLens::Kind::Model:
            return k.lensProjection(lens.model, lens.coefficients, kPlaceholderNear, kPlaceholderFar, "intrinsics");
        case FrameLens::Kind::Panorama: return panorama(k, width, height);
        case FrameLens::Kind::Sphere: {
            k.projection(kPlaceholderNear, kPlaceholderFar, "intrinsics");
            Projection p;
            p.type = ProjectionType::NonLinear;
            p.lens = {"equirectangular", {-180, 180, -90, 90}};  // latlong_to_dir: u = ½ forward, v = 0 up
            p.near = kPlaceholderNear, p.far = kPlaceholderFar;
            return p;
        }
        }
        return k.projection(kPlaceholderNear, kPlaceholderFar, "intrinsics");
    }

    // ---- the pose and the frame ----------------------------------------------------------

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
        const FrameLens lens = lensOf(frame, where);
        const auto projectionFor = [given, lens, at = source() + " " + where + ": "](int width, int height) {
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
            try {
                return projectionWith(lens, k, width, height);
            } catch (const Error& e) {  // resolved later against the depth map's size: say where
                throw Error(at + e.what());
            }
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
        camera.refusal = lens.refusal;
        spec.notes.insert(spec.notes.end(), lens.notes.begin(), lens.notes.end());
        return camera;
    }

    std::string path_;
    json root_;
    const json* frames_ = nullptr;
};

// ---- the writer ---------------------------------------------------------------------------

[[noreturn]] void refuseLens(const LensModel& lens, const std::string& why)
{
    throw Error("lens model " + lens.spec().model + " cannot be written as nerfstudio's transforms.json: " + why);
}

// The first of `names` that is not 0, refused as what nerfstudio's camera_model `target` lacks.
void requireZero(const LensModel& lens, std::initializer_list<const char*> names, const std::string& target,
                 const std::string& why)
{
    for (const char* name : names)
        if (lens.param(name) != 0)
            refuseLens(lens, std::string(name) + " = " + formatNumber(lens.param(name)) + ", which camera_model " + target +
                                 " has no place for (" + why + ")");
}

// The camera_model and its keys for a camera's lens, where nerfstudio has the model exactly.
void writeLens(const Camera& camera, json& document)
{
    const LensModel& lens = *camera.lens();
    const std::string& model = lens.spec().model;
    const auto p = [&](const char* name) { return lens.param(name); };
    if (model == "brown_conrady" || model == "opencv") {
        if (model == "opencv")
            requireZero(lens, {"k4", "k5", "k6", "s1", "s2", "s3", "s4", "tau_x", "tau_y"}, "OPENCV",
                        "OpenCV's k4..k6 are a rational denominator, nerfstudio's k4 an r⁸ term; nor has it thin prism or "
                        "tilt");
        document["camera_model"] = "OPENCV";
        for (const char* key : {"k1", "k2", "k3", "k4", "p1", "p2"}) document[key] = p(key);
    } else if (model == "opencv_fisheye" || model == "thin_prism_fisheye") {
        requireZero(lens, {"sx1", "sy1"}, "OPENCV_FISHEYE", "nerfstudio's fisheye has no thin prism");
        document["camera_model"] = "OPENCV_FISHEYE";
        for (const char* key : {"k1", "k2", "k3", "k4"}) document[key] = p(key);
        if (p("p1") != 0 || p("p2") != 0) document["p1"] = p("p1"), document["p2"] = p("p2");
    } else if (model == "metashape_frame" || model == "metashape_fisheye") {
        // fx = f + b1 (pinholeIntrinsicsOf's K); Metashape's P1 is OpenCV's p2.
        requireZero(lens, {"b2"}, model == "metashape_frame" ? "OPENCV" : "OPENCV_FISHEYE", "a skew");
        document["camera_model"] = model == "metashape_frame" ? "OPENCV" : "OPENCV_FISHEYE";
        for (const char* key : {"k1", "k2", "k3", "k4"}) document[key] = p(key);
        document["p1"] = p("p2"), document["p2"] = p("p1");
    } else if (model == "fisheye624") {
        document["camera_model"] = "FISHEYE624";
        json list = json::array();
        for (const char* key : {"k0", "k1", "k2", "k3", "k4", "k5", "p0", "p1", "s0", "s1", "s2", "s3"})
            list.push_back(p(key));
        document["distortion_params"] = list;
    } else {
        refuseLens(lens, "nerfstudio's camera models are OPENCV (brown_conrady; opencv without k4..k6, thin prism or "
                         "tilt), OPENCV_FISHEYE (opencv_fisheye, thin_prism_fisheye without sx1, sy1), FISHEYE624 and "
                         "EQUIRECTANGULAR");
    }
}

// nerfstudio's EQUIRECTANGULAR for a panorama: the fl_x, cx, fl_y, cy whose longitudes and
// latitudes (the reader's panorama()) are the lens's.
void writePanorama(const Camera& camera, json& document)
{
    const LensModel& lens = *camera.lens();
    const double lonMin = lens.param("lon_min_deg"), lonMax = lens.param("lon_max_deg");
    const double latMin = lens.param("lat_min_deg"), latMax = lens.param("lat_max_deg");
    const double fx = 180 * camera.width() / (lonMax - lonMin), fy = 180 * camera.height() / (latMax - latMin);
    document["camera_model"] = "EQUIRECTANGULAR";
    document["fl_x"] = fx, document["fl_y"] = fy;
    document["cx"] = -lonMin * fx / 180, document["cy"] = latMax * fy / 180;
}

// transforms.json: camera_model, fl_x, fl_y, cx, cy, w, h, the lens's keys and one frame whose
// transform_matrix is camera-to-world in OpenGL axes.
std::vector<CameraFileText> writeTransformsJson(const Camera& camera, const std::string& name)
{
    json document = json::object();
    if (camera.lens() && camera.lens()->isPanorama()) {
        writePanorama(camera, document);
    } else if (camera.lens()) {  // the chain's fx, fy, cx, cy (Metashape's f + b1, f among them)
        const LensModel::Terms& t = camera.lens()->terms();
        document["fl_x"] = t.fx, document["fl_y"] = t.fy, document["cx"] = t.cx + 0.5, document["cy"] = t.cy + 0.5;
        writeLens(camera, document);
    } else {
        const PinholeIntrinsics k = pinholeIntrinsicsOf(camera, 0.5);
        document["camera_model"] = "PINHOLE";
        document["fl_x"] = k.fx, document["fl_y"] = k.fy, document["cx"] = k.cx, document["cy"] = k.cy;
    }
    const glm::dmat4 worldFromCam = rigidInverse(camFromWorldIn(camera, Convention::preset("opengl")));
    json rows = json::array();
    for (int r = 0; r < 4; ++r)
        rows.push_back(json::array({worldFromCam[0][r], worldFromCam[1][r], worldFromCam[2][r], worldFromCam[3][r]}));
    document["w"] = camera.width(), document["h"] = camera.height();
    document["frames"] = json::array({{{"file_path", name}, {"transform_matrix", rows}}});
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
