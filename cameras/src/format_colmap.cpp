// COLMAP sparse models (colmap.github.io/format.html), text and binary, as COLMAP writes them.
//
//   pose    world-to-camera: p_cam = R(qvec)·p_world + tvec, qvec = (qw, qx, qy, qz), a
//           Hamilton quaternion with the scalar first
//   axes    OpenCV: x right, y down, z forward
//   pixels  the image's top-left corner is (0, 0), so the centre of the top-left pixel is
//           (0.5, 0.5) and a centred camera has cx = W/2 (models.h in COLMAP says so)
//   units   the model's own
//
//   cameras.txt  "CAMERA_ID MODEL WIDTH HEIGHT PARAMS..." per line; '#' lines are comments
//   images.txt   two lines per image: "IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME", then
//                its 2-D points (possibly an empty line), which zcheck does not need
//   cameras.bin  uint64 count; per camera uint32 camera_id, int32 model_id, uint64 width,
//                uint64 height, double params[n(model)]
//   images.bin   uint64 count; per image uint32 image_id, double qvec[4], double tvec[3],
//                uint32 camera_id, a NUL-terminated name, uint64 num_points2D and that many
//                (double x, double y, uint64 point3D_id)
// All little-endian. Every count is checked against the bytes present before anything is
// allocated, and every message names the file and the line (text) or byte offset (binary).
//
// Camera models (COLMAP src/colmap/sensor/models.h, read at commit 5d968cf3 of 2026-08-08: each
// model's parameter list, ImgFromCam and Distortion), as zcheck lens models (lens.h), the
// parameters after fx, fy, cx, cy (f, cx, cy) kept in COLMAP's order:
//
//   SIMPLE_PINHOLE, PINHOLE       pinhole
//   SIMPLE_RADIAL, RADIAL         opencv k1 (k2): m·(1 + k1r² + k2r⁴) on m = (x/z, y/z), fx = fy = f
//   OPENCV                        opencv k1 k2 p1 p2 (OpenCV's tangential pairing: 2p1xy + p2(r²+2x²))
//   FULL_OPENCV                   opencv k1 k2 p1 p2 k3 k4 k5 k6 (OpenCV's order; rational radial)
//   OPENCV_FISHEYE                opencv_fisheye k1..k4: θ·(1 + k1θ² + … + k4θ⁸) on the equidistant point
//   SIMPLE_RADIAL_FISHEYE,        opencv_fisheye k1 (k2): θ·(1 + k1θ² + k2θ⁴), the same polynomial cut
//   RADIAL_FISHEYE                short
//   SIMPLE_FISHEYE, FISHEYE       opencv_fisheye with no coefficients: equidistant, still a fisheye
//   THIN_PRISM_FISHEYE            thin_prism_fisheye k1 k2 p1 p2 k3 k4 sx1 sy1: radial, tangential and
//                                 prism all on the equidistant point
//   RAD_TAN_THIN_PRISM_FISHEYE    fisheye624 k0..k5 p0 p1 s0..s3: tangential and prism on the point after
//                                 the radial polynomial, p0 with r² + 2x² (Aria's FISHEYE624, same order)
//   FOV                           fov omega: r ↦ atan(2r·tan(ω/2))/ω. The formula is even in ω and COLMAP's
//                                 bundle adjustment leaves ω negative at times (colmap issue 1261): |ω|
//   SIMPLE_DIVISION, DIVISION     division k: the ray through m is (m, 1 + k|m|²)
//   EUCM                          eucm alpha beta: m = (x, y)/(α·√(β(x²+y²) + z²) + (1 − α)z)
//   EQUIRECTANGULAR (id 17)       equirectangular −180..180° longitude, −90..90° latitude; its
//                                 parameters w, h are the image size its mapping spans
// COLMAP's pixel coordinates put the image's top-left corner at (0, 0) (models.h's convention
// note), as zcheck's image coordinates do: cx, cy move by ½ into the lens's OpenCV coordinates.
// A non-fisheye model whose distortion is nothing (every coefficient 0; FOV ω = 0, its pinhole
// limit; EUCM α = 0 with β ≥ 0) is a linear pinhole. A camera zcheck cannot use (a lens that
// folds inside the image or is out of its parameters' ranges, an EQUIRECTANGULAR whose w, h are
// not the camera's size) is kept with its refusal (camera_import.h): only the images that use it
// fail. Malformed input (a parameter count, a number, a focal length ≤ 0) fails the whole model.
//
// Writing (zcheck camera --to colmap): a linear camera as PINHOLE; a lens as the COLMAP model of
// the same formula: opencv as OPENCV (k1 k2 p1 p2) or FULL_OPENCV (any of k3..k6 nonzero),
// brown_conrady and metashape_frame without k4 likewise (Metashape's f + b1, f as fx, fy, its
// P1, P2 as OpenCV's p2, p1), metashape_fisheye as OPENCV_FISHEYE (P1 = P2 = 0) or
// THIN_PRISM_FISHEYE, opencv_fisheye, thin_prism_fisheye, fisheye624, fov, division and eucm as
// theirs, the whole-sphere equirectangular as EQUIRECTANGULAR W H W H. The rest (thin prism or
// tilt in opencv, an r⁸ term on the perspective point, Metashape's skew b2, unified, double
// sphere, equisolid, a partial panorama) is refused naming the model and the coefficient.
//
// Where COLMAP and zcheck part (beyond what a sane calibration's image shows): COLMAP's ImgFromCam
// rejects points with z ≤ ε for every model but DIVISION and EQUIRECTANGULAR, and its fisheyes'
// CamFromImg do not lift pixels beyond θ = 90°; zcheck's lens keeps a fisheye's or EUCM's field
// out to where the model stops being one-to-one, past 90° where the coefficients allow. COLMAP's
// FOV Distortion, for |ω| < 0.01, uses the series of the inverse map (1 − ω²/12 + ω²r²/3, where
// the forward map's is 1 + ω²/12 − ω²r²/3); zcheck uses the closed form, as COLMAP's CamFromImg does.
#include "formats.h"

#include "zcheck/camera.h"
#include "zcheck/error.h"
#include "zcheck/input_file.h"
#include "zcheck/large_buffer.h"
#include "zcheck/pose.h"

#include <sys/stat.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <sstream>
#include <utility>

namespace zcheck::formats {

const CameraFormat& colmapFormat();

namespace {

using Coefficients = std::vector<double>;

bool allZero(const Coefficients& c)
{
    for (double v : c)
        if (v != 0) return false;
    return true;
}
// EUCM with α = 0 is m = (x, y)/z for any β ≥ 0 (β < 0 is out of COLMAP's range and zcheck's).
bool eucmIsPinhole(const Coefficients& c) { return c[0] == 0 && c[1] >= 0; }

struct ModelInfo {
    int id;
    const char* name;
    std::vector<const char*> params;  // COLMAP's, in order (models.h, InitializeParamsInfo)
    int focals;                       // 1: f for fx and fy; 2: fx, fy; 0: none (a panorama)
    const char* lens;                 // the zcheck lens model of its coefficients; nullptr: a pinhole
    bool (*isPinhole)(const Coefficients&);  // when its coefficients make it linear; nullptr: never
};

const std::vector<ModelInfo>& models()
{
    static const std::vector<ModelInfo> table = {
        {0, "SIMPLE_PINHOLE", {"f", "cx", "cy"}, 1, nullptr, allZero},
        {1, "PINHOLE", {"fx", "fy", "cx", "cy"}, 2, nullptr, allZero},
        {2, "SIMPLE_RADIAL", {"f", "cx", "cy", "k"}, 1, "opencv", allZero},
        {3, "RADIAL", {"f", "cx", "cy", "k1", "k2"}, 1, "opencv", allZero},
        {4, "OPENCV", {"fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2"}, 2, "opencv", allZero},
        {5, "OPENCV_FISHEYE", {"fx", "fy", "cx", "cy", "k1", "k2", "k3", "k4"}, 2, "opencv_fisheye", nullptr},
        {6, "FULL_OPENCV", {"fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6"}, 2, "opencv", allZero},
        {7, "FOV", {"fx", "fy", "cx", "cy", "omega"}, 2, "fov", allZero},
        {8, "SIMPLE_RADIAL_FISHEYE", {"f", "cx", "cy", "k"}, 1, "opencv_fisheye", nullptr},
        {9, "RADIAL_FISHEYE", {"f", "cx", "cy", "k1", "k2"}, 1, "opencv_fisheye", nullptr},
        {10, "THIN_PRISM_FISHEYE", {"fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3", "k4", "sx1", "sy1"}, 2,
         "thin_prism_fisheye", nullptr},
        {11, "RAD_TAN_THIN_PRISM_FISHEYE",
         {"fx", "fy", "cx", "cy", "k0", "k1", "k2", "k3", "k4", "k5", "p0", "p1", "s0", "s1", "s2", "s3"}, 2, "fisheye624",
         nullptr},
        {12, "SIMPLE_DIVISION", {"f", "cx", "cy", "k"}, 1, "division", allZero},
        {13, "DIVISION", {"fx", "fy", "cx", "cy", "k"}, 2, "division", allZero},
        {14, "SIMPLE_FISHEYE", {"f", "cx", "cy"}, 1, "opencv_fisheye", nullptr},
        {15, "FISHEYE", {"fx", "fy", "cx", "cy"}, 2, "opencv_fisheye", nullptr},
        {16, "EUCM", {"fx", "fy", "cx", "cy", "alpha", "beta"}, 2, "eucm", eucmIsPinhole},
        {17, "EQUIRECTANGULAR", {"w", "h"}, 0, "equirectangular", nullptr},
    };
    return table;
}

const ModelInfo* modelById(std::int64_t id)
{
    for (const ModelInfo& m : models())
        if (m.id == id) return &m;
    return nullptr;
}

const ModelInfo* modelByName(const std::string& name)
{
    for (const ModelInfo& m : models())
        if (name == m.name) return &m;
    return nullptr;
}

std::size_t paramCount(const ModelInfo& m) { return m.params.size(); }

// "fx, fy, cx, cy": a model's parameters, for messages.
std::string paramNames(const ModelInfo& m)
{
    std::string out;
    for (const char* name : m.params) out += (out.empty() ? "" : ", ") + std::string(name);
    return out;
}

std::string modelNames()
{
    std::string out;
    for (const ModelInfo& m : models()) out += (out.empty() ? "" : ", ") + std::string(m.name);
    return out;
}

// COLMAP's EQUIRECTANGULAR (EquirectangularCameraModel::ImgFromCam): x = (atan2(u, w)/2π + ½)·w_param,
// y = (½ − atan2(−v, √(u² + w²))/π)·h_param, so over an image of w_param × h_param pixels it is
// zcheck's equirectangular across the whole sphere.
const LensSpec kFullSphere{"equirectangular", {-180, 180, -90, 90}};

struct ColmapCamera {
    std::int64_t width = 0, height = 0;
    Projection projection;  // a pinhole or a lens model (the pinhole of its K when it is refused)
    std::string refusal;    // why the images that use it cannot be checked; "" none
};

// A camera as zcheck sees it. `where` names the line or record. An impossible value (a focal
// length ≤ 0, a principal point beyond what binary32 rays can hold) throws, whichever image
// uses the camera; a lens zcheck refuses (LensModel's own rules) becomes the camera's refusal.
ColmapCamera cameraOf(const ModelInfo& model, std::int64_t width, std::int64_t height, const std::vector<double>& p,
                      const std::string& where)
{
    ColmapCamera camera;
    camera.width = width, camera.height = height;
    CameraSpec spec;
    spec.convention = Convention::preset("opencv");
    spec.width = int(width), spec.height = int(height);
    spec.view.hasMatrix = true;
    const auto validated = [&](const Projection& projection) {
        spec.projection = projection;
        const Camera built(spec);
        return projection;
    };
    if (model.focals == 0) {  // EQUIRECTANGULAR: w, h
        Projection panorama;
        panorama.type = ProjectionType::NonLinear;
        panorama.lens = kFullSphere;
        panorama.near = kPlaceholderNear, panorama.far = kPlaceholderFar;
        try {
            camera.projection = validated(panorama);
        } catch (const Error& e) {
            throw Error(where + ": " + e.what());
        }
        if (p[0] != double(width) || p[1] != double(height))
            camera.refusal = where + ": camera model EQUIRECTANGULAR has w = " + formatNumber(p[0]) + ", h = " +
                             formatNumber(p[1]) + " for an image of " + std::to_string(width) + "x" +
                             std::to_string(height) + ": COLMAP spreads longitude -180..180° over w pixels and latitude "
                             "90..-90° over h, which would not span this image; zcheck reads it with w, h the "
                             "camera's width and height";
        return camera;
    }
    const std::size_t f = std::size_t(model.focals);
    const PinholeIntrinsics k{p[0], p[f == 1 ? 0 : 1], p[f], p[f + 1], 0.5};
    try {
        camera.projection = validated(k.projection(kPlaceholderNear, kPlaceholderFar, "intrinsics"));
    } catch (const Error& e) {
        throw Error(where + ": " + e.what());
    }
    Coefficients coefficients(p.begin() + std::ptrdiff_t(f + 2), p.end());
    if (!model.lens || (model.isPinhole && model.isPinhole(coefficients))) return camera;
    if (std::string(model.name) == "FOV") coefficients[0] = std::abs(coefficients[0]);
    try {
        camera.projection =
            validated(k.lensProjection(model.lens, coefficients, kPlaceholderNear, kPlaceholderFar, "intrinsics"));
    } catch (const Error& e) {
        camera.refusal = where + ": camera model " + model.name + ": " + e.what();
    }
    return camera;
}

struct ColmapImage {
    std::string name;
    double q[4] = {1, 0, 0, 0};
    double t[3] = {0, 0, 0};
    std::int64_t cameraId = 0;
    std::string where;  // "images.txt line 7", "images.bin image 3"
};

// ---- text ----------------------------------------------------------------------------

std::vector<std::string> tokens(const std::string& line)
{
    std::vector<std::string> out;
    std::istringstream in(line);
    for (std::string token; in >> token;) out.push_back(token);
    return out;
}

std::string trimmed(const std::string& line)
{
    const std::size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos) return "";
    return line.substr(first, line.find_last_not_of(" \t\r") - first + 1);
}

class TextFile {
public:
    TextFile(const std::string& path) : path_(path), name_(path.substr(path.find_last_of('/') + 1))
    {
        std::istringstream in(readInputFile(path, colmapFormat().input));
        for (std::string line; std::getline(in, line);) lines_.push_back(trimmed(line));
    }
    std::size_t size() const { return lines_.size(); }
    const std::string& line(std::size_t i) const { return lines_[i]; }
    std::string where(std::size_t i) const { return "COLMAP " + name_ + " line " + std::to_string(i + 1); }
    [[noreturn]] void fail(std::size_t i, const std::string& why) const
    {
        throw Error("cannot read COLMAP model file '" + path_ + "': line " + std::to_string(i + 1) + ": " + why);
    }
    double number(std::size_t i, const std::string& token, const std::string& what) const
    {
        double value = 0;
        if (!parseFiniteNumber(token, value)) fail(i, what + " '" + printableExcerpt(token, 40) + "' is not a finite number");
        return value;
    }
    std::int64_t integer(std::size_t i, const std::string& token, const std::string& what, std::int64_t max,
                         std::int64_t min = 0) const
    {
        const double value = number(i, token, what);
        if (value != std::floor(value) || value < double(min) || value > double(max))
            fail(i, what + " '" + token + "' is not an integer in " + std::to_string(min) + ".." + std::to_string(max));
        return std::int64_t(value);
    }

private:
    std::string path_, name_;
    std::vector<std::string> lines_;
};

bool isData(const std::string& line) { return !line.empty() && line[0] != '#'; }

std::map<std::int64_t, ColmapCamera> readCamerasText(const std::string& path)
{
    const TextFile file(path);
    std::map<std::int64_t, ColmapCamera> cameras;
    for (std::size_t i = 0; i < file.size(); ++i) {
        if (!isData(file.line(i))) continue;
        const std::vector<std::string> t = tokens(file.line(i));
        if (t.size() < 4) file.fail(i, "a camera line needs CAMERA_ID MODEL WIDTH HEIGHT PARAMS...");
        const std::int64_t id = file.integer(i, t[0], "CAMERA_ID", 0xFFFFFFFF);
        const ModelInfo* model = modelByName(t[1]);
        if (!model) file.fail(i, "unknown camera model '" + printableExcerpt(t[1], 40) + "' (COLMAP's are " + modelNames() + ")");
        const std::int64_t width = file.integer(i, t[2], "WIDTH", Camera::kMaxImageSide, 1),
                           height = file.integer(i, t[3], "HEIGHT", Camera::kMaxImageSide, 1);
        if (t.size() - 4 != paramCount(*model))
            file.fail(i, std::string("camera model ") + model->name + " takes " + std::to_string(paramCount(*model)) +
                             " parameters, the line has " + std::to_string(t.size() - 4) + " (" + model->name + ": " +
                             paramNames(*model) + ")");
        std::vector<double> params;
        for (std::size_t k = 4; k < t.size(); ++k) params.push_back(file.number(i, t[k], "parameter " + std::to_string(k - 3)));
        if (cameras.count(id)) file.fail(i, "CAMERA_ID " + std::to_string(id) + " appears twice");
        cameras[id] = cameraOf(*model, width, height, params, file.where(i) + " (camera " + std::to_string(id) + ")");
    }
    return cameras;
}

std::vector<ColmapImage> readImagesText(const std::string& path)
{
    const TextFile file(path);
    std::vector<ColmapImage> images;
    for (std::size_t i = 0; i < file.size(); ++i) {
        if (!isData(file.line(i))) continue;
        // IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME: the name is the rest of the line.
        std::istringstream in(file.line(i));
        std::vector<std::string> t(9);
        for (std::string& token : t) in >> token;
        std::string name;
        std::getline(in, name);
        name = trimmed(name);
        if (t[8].empty() || name.empty()) file.fail(i, "an image line needs IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME");
        ColmapImage image;
        file.integer(i, t[0], "IMAGE_ID", 0xFFFFFFFF);
        for (int k = 0; k < 4; ++k) image.q[k] = file.number(i, t[std::size_t(1 + k)], "qvec");
        for (int k = 0; k < 3; ++k) image.t[k] = file.number(i, t[std::size_t(5 + k)], "tvec");
        image.cameraId = file.integer(i, t[8], "CAMERA_ID", 0xFFFFFFFF);
        image.name = name;
        image.where = file.where(i);
        images.push_back(image);
        ++i;  // the POINTS2D line that follows every image line, empty or not
    }
    return images;
}

// ---- binary --------------------------------------------------------------------------

class BinaryFile {
public:
    BinaryFile(const std::string& path) : path_(path), bytes_(readInputBytes(path, colmapFormat().input)) {}
    std::uint64_t remaining() const { return bytes_.size() - at_; }
    std::uint64_t offset() const { return at_; }
    [[noreturn]] void fail(const std::string& why) const
    {
        throw Error("cannot read COLMAP model file '" + path_ + "': " + why);
    }
    void need(std::uint64_t n, const std::string& what) const
    {
        if (remaining() < n)
            fail(what + " at byte " + std::to_string(at_) + " needs " + std::to_string(n) + " bytes, " +
                 std::to_string(remaining()) + " remain (the file is cut short)");
    }
    template <class T>
    T read(const std::string& what)
    {
        need(sizeof(T), what);
        T value;
        std::memcpy(&value, bytes_.data() + at_, sizeof(T));  // little-endian, as the host (x86-64)
        at_ += sizeof(T);
        return value;
    }
    double finite(const std::string& what)
    {
        const double value = read<double>(what);
        if (!std::isfinite(value)) fail(what + " at byte " + std::to_string(at_ - 8) + " is not finite");
        return value;
    }
    std::string cString(const std::string& what)
    {
        const char* begin = bytes_.data() + at_;
        const void* nul = std::memchr(begin, '\0', std::size_t(remaining()));
        if (!nul) fail(what + " at byte " + std::to_string(at_) + " has no terminating NUL before the end of the file");
        const std::string text(begin, static_cast<const char*>(nul));
        at_ += text.size() + 1;
        return text;
    }
    void skip(std::uint64_t n) { at_ += n; }

private:
    std::string path_;
    LargeVector<char> bytes_;
    std::uint64_t at_ = 0;
};

std::map<std::int64_t, ColmapCamera> readCamerasBinary(const std::string& path)
{
    BinaryFile file(path);
    const std::uint64_t count = file.read<std::uint64_t>("the camera count");
    if (count > file.remaining() / 24)
        file.fail("it declares " + std::to_string(count) + " cameras, more than its " + std::to_string(file.remaining()) +
                  " remaining bytes can hold");
    std::map<std::int64_t, ColmapCamera> cameras;
    for (std::uint64_t c = 0; c < count; ++c) {
        const std::string what = "camera record " + std::to_string(c);
        const std::int64_t id = file.read<std::uint32_t>(what);
        const std::int32_t modelId = file.read<std::int32_t>(what);
        const ModelInfo* model = modelById(modelId);
        if (!model)
            file.fail(what + " (camera " + std::to_string(id) + ") has model id " + std::to_string(modelId) +
                      ", which zcheck does not know (COLMAP's 0..17: " + modelNames() + ")");
        const std::uint64_t width = file.read<std::uint64_t>(what), height = file.read<std::uint64_t>(what);
        if (!Camera::isImageSide(double(width)) || !Camera::isImageSide(double(height)))
            file.fail(what + " (camera " + std::to_string(id) + ") has the size " + std::to_string(width) + "x" +
                      std::to_string(height) + ", outside 1.." + std::to_string(Camera::kMaxImageSide) + " per side");
        std::vector<double> params;
        for (std::size_t k = 0; k < paramCount(*model); ++k) params.push_back(file.finite(what + " parameter " + std::to_string(k)));
        if (cameras.count(id)) file.fail(what + ": camera id " + std::to_string(id) + " appears twice");
        const std::string where = "COLMAP cameras.bin camera " + std::to_string(id);
        cameras[id] = cameraOf(*model, std::int64_t(width), std::int64_t(height), params, where);
    }
    return cameras;
}

std::vector<ColmapImage> readImagesBinary(const std::string& path)
{
    BinaryFile file(path);
    const std::uint64_t count = file.read<std::uint64_t>("the image count");
    constexpr std::uint64_t kFixed = 4 + 7 * 8 + 4 + 1 + 8;  // an image record without name and points
    if (count > file.remaining() / kFixed)
        file.fail("it declares " + std::to_string(count) + " images, more than its " + std::to_string(file.remaining()) +
                  " remaining bytes can hold");
    std::vector<ColmapImage> images;
    images.reserve(std::size_t(count));
    for (std::uint64_t i = 0; i < count; ++i) {
        const std::string what = "image record " + std::to_string(i);
        ColmapImage image;
        const std::uint32_t id = file.read<std::uint32_t>(what);
        for (double& q : image.q) q = file.finite(what + " qvec");
        for (double& t : image.t) t = file.finite(what + " tvec");
        image.cameraId = file.read<std::uint32_t>(what);
        image.name = file.cString(what + " name");
        const std::uint64_t points = file.read<std::uint64_t>(what + " point count");
        if (points > file.remaining() / 24)
            file.fail(what + " declares " + std::to_string(points) + " 2-D points, more than the " +
                      std::to_string(file.remaining()) + " remaining bytes hold");
        file.skip(points * 24);
        image.where = "COLMAP images.bin image " + std::to_string(id) + " ('" + printableExcerpt(image.name, 80) + "')";
        images.push_back(image);
    }
    if (file.remaining() != 0)
        file.fail(std::to_string(file.remaining()) + " bytes follow the last of its " + std::to_string(count) + " images");
    return images;
}

bool isFile(const std::string& path)
{
    struct stat status {};
    return ::stat(path.c_str(), &status) == 0 && S_ISREG(status.st_mode);
}

bool isFolder(const std::string& path)
{
    struct stat status {};
    return ::stat(path.c_str(), &status) == 0 && S_ISDIR(status.st_mode);
}

// The folder of a COLMAP model named by the folder or one of its files; "" if `path` is neither.
std::string colmapModelFolder(const std::string& path)
{
    auto holdsModel = [](const std::string& folder) {
        return (isFile(folder + "/cameras.bin") && isFile(folder + "/images.bin")) ||
               (isFile(folder + "/cameras.txt") && isFile(folder + "/images.txt"));
    };
    if (isFolder(path)) return holdsModel(path) ? path : "";
    const std::size_t slash = path.find_last_of('/');
    const std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
    const std::string folder = slash == std::string::npos ? "." : path.substr(0, slash);
    for (const char* file : {"cameras.bin", "images.bin", "cameras.txt", "images.txt", "points3D.bin", "points3D.txt"})
        if (name == file && holdsModel(folder)) return folder;
    return "";
}

CameraSet readColmapModel(const std::string& path)
{
    const std::string folder = colmapModelFolder(path);
    if (folder.empty())
        throw Error("'" + path + "' is not a COLMAP model: a model is a folder with cameras.bin and images.bin, or "
                                 "cameras.txt and images.txt");
    const bool binary = isFile(folder + "/cameras.bin") && isFile(folder + "/images.bin");
    const auto cameras = binary ? readCamerasBinary(folder + "/cameras.bin") : readCamerasText(folder + "/cameras.txt");
    const auto images = binary ? readImagesBinary(folder + "/images.bin") : readImagesText(folder + "/images.txt");

    CameraSet set;
    set.path = path;
    const Convention opencv = Convention::preset("opencv");
    for (const ColmapImage& image : images) {
        ImportedCamera camera;
        camera.name = image.name;
        camera.aliases = pathAliases(image.name);
        const auto found = cameras.find(image.cameraId);
        if (found == cameras.end())
            throw Error(image.where + ": CAMERA_ID " + std::to_string(image.cameraId) + " is not in the model's cameras");
        const ColmapCamera& intrinsics = found->second;
        camera.refusal = intrinsics.refusal.empty() ? "" : image.where + " uses " + intrinsics.refusal;
        CameraSpec& spec = camera.spec;
        spec.convention = opencv;
        spec.width = int(intrinsics.width), spec.height = int(intrinsics.height);
        try {
            spec.projection = intrinsics.projection;
            double departure = 0;
            const glm::dmat4 camFromWorld = poseFromRotationTranslation(
                rotationFromQuaternion(image.q[0], image.q[1], image.q[2], image.q[3], "qvec", &departure),
                {image.t[0], image.t[1], image.t[2]});
            spec.view = viewFromPose(camFromWorld, PoseDirection::CameraFromWorld, opencv, opencv, "qvec, tvec");
            spec.view.rotationDeparture = std::max(spec.view.rotationDeparture, departure);
            // The lens was validated with its camera (cameraOf); the pose is validated here with a
            // linear stand-in, so that a model of thousands of images builds its lens once.
            CameraSpec pose = spec;
            if (pose.projection.type == ProjectionType::NonLinear)
                pose.projection = Projection::perspective(60, kPlaceholderNear, kPlaceholderFar);
            Camera validated(pose);
        } catch (const Error& e) {
            throw Error(image.where + ": " + e.what());
        }
        set.cameras.push_back(std::move(camera));
    }
    return set;
}

// The COLMAP model that holds a camera exactly, and its parameters: PINHOLE for a linear camera;
// for a lens model the COLMAP model of the same formula (cameraOf's table read backwards), the
// principal point moved to COLMAP's corner-origin pixels. Throws naming the lens model (and the
// coefficient) where COLMAP has none.
std::pair<const ModelInfo*, std::vector<double>> colmapModelOf(const Camera& camera)
{
    const LensModel* lens = camera.lens();
    if (!lens) {
        const PinholeIntrinsics k = pinholeIntrinsicsOf(camera, 0.5);
        return {modelByName("PINHOLE"), {k.fx, k.fy, k.cx, k.cy}};
    }
    const std::string& name = lens->spec().model;
    const std::vector<double>& q = lens->spec().params;  // every parameter, in the model's order (lens.h)
    const auto refuse = [&](const std::string& why) -> std::pair<const ModelInfo*, std::vector<double>> {
        throw Error("cannot write lens model " + name + " as a COLMAP camera: " + why);
    };
    const auto nonzero = [&](std::size_t from, std::size_t to) -> const char* {  // the first nonzero of q[from, to)
        for (std::size_t i = from; i < to; ++i)
            if (q[i] != 0) return lens->info().params[i];
        return nullptr;
    };
    const auto named = [&](const char* model, std::vector<double> coefficients) {
        const PinholeIntrinsics k = pinholeIntrinsicsOf(camera, 0.5);
        std::vector<double> params = {k.fx, k.fy, k.cx, k.cy};
        params.insert(params.end(), coefficients.begin(), coefficients.end());
        return std::pair{modelByName(model), params};
    };
    const auto slice = [&](std::size_t from, std::size_t to) {
        return std::vector<double>(q.begin() + std::ptrdiff_t(from), q.begin() + std::ptrdiff_t(to));
    };
    if (name == "opencv") {  // fx fy cx cy k1 k2 p1 p2 k3 k4 k5 k6 s1 s2 s3 s4 tau_x tau_y
        if (const char* c = nonzero(12, 18))
            return refuse(std::string(c) + " = " + formatNumber(lens->param(c)) +
                          ": COLMAP's OPENCV and FULL_OPENCV have no thin prism (s1..s4) or tilt (tau_x, tau_y)");
        return nonzero(8, 12) ? named("FULL_OPENCV", slice(4, 12)) : named("OPENCV", slice(4, 8));
    }
    if (name == "brown_conrady") {  // fx fy cx cy k1 k2 k3 k4 p1 p2: OpenCV's with k3 and an r⁸ term k4
        if (q[7] != 0)
            return refuse("k4 = " + formatNumber(q[7]) + ": COLMAP's models have no r⁸ term on the perspective point");
        if (q[6] != 0) return named("FULL_OPENCV", {q[4], q[5], q[8], q[9], q[6], 0, 0, 0});
        return named("OPENCV", {q[4], q[5], q[8], q[9]});
    }
    if (name == "metashape_frame" || name == "metashape_fisheye") {
        // f cx cy b1 b2 k1 k2 k3 k4 p1 p2: fx = f + b1, fy = f, skew b2, and Metashape's P1 is
        // OpenCV's p2 (lens.h) — OpenCV's models with the pair swapped, where b2 is 0.
        if (q[4] != 0) return refuse("b2 = " + formatNumber(q[4]) + ": COLMAP's models have no skew");
        const std::vector<double> k = {q[0] + q[3], q[0], q[1] + 0.5, q[2] + 0.5};
        const auto withK = [&](const char* model, const std::vector<double>& coefficients) {
            std::vector<double> params = k;
            params.insert(params.end(), coefficients.begin(), coefficients.end());
            return std::pair{modelByName(model), params};
        };
        if (name == "metashape_fisheye") {  // KB on the equidistant point, tangential on it too
            if (q[9] == 0 && q[10] == 0) return withK("OPENCV_FISHEYE", {q[5], q[6], q[7], q[8]});
            return withK("THIN_PRISM_FISHEYE", {q[5], q[6], q[10], q[9], q[7], q[8], 0, 0});
        }
        if (q[8] != 0)
            return refuse("k4 = " + formatNumber(q[8]) + ": COLMAP's models have no r⁸ term on the perspective point");
        if (q[7] != 0) return withK("FULL_OPENCV", {q[5], q[6], q[10], q[9], q[7], 0, 0, 0});
        return withK("OPENCV", {q[5], q[6], q[10], q[9]});
    }
    if (name == "opencv_fisheye") return named("OPENCV_FISHEYE", slice(4, 8));
    if (name == "thin_prism_fisheye") return named("THIN_PRISM_FISHEYE", slice(4, 12));
    if (name == "fisheye624") return named("RAD_TAN_THIN_PRISM_FISHEYE", slice(4, 16));
    if (name == "fov") return named("FOV", slice(4, 5));
    if (name == "division") return named("DIVISION", slice(4, 5));
    if (name == "eucm") return named("EUCM", slice(4, 6));
    if (name == "equirectangular") {
        if (lens->spec() != kFullSphere)
            return refuse("it spans longitude " + formatNumber(q[0]) + ".." + formatNumber(q[1]) + "° and latitude " +
                          formatNumber(q[2]) + ".." + formatNumber(q[3]) +
                          "°; COLMAP's EQUIRECTANGULAR spans the whole sphere, -180..180° and -90..90°");
        return {modelByName("EQUIRECTANGULAR"), {double(camera.width()), double(camera.height())}};
    }
    return refuse("COLMAP has no camera model of its formula (it has OPENCV, FULL_OPENCV, OPENCV_FISHEYE, "
                  "THIN_PRISM_FISHEYE, RAD_TAN_THIN_PRISM_FISHEYE, FOV, DIVISION, EUCM and EQUIRECTANGULAR: zcheck's "
                  "opencv without thin prism or tilt, brown_conrady and metashape_frame without k4, metashape_* "
                  "without b2, opencv_fisheye, thin_prism_fisheye, fisheye624, fov, division, eucm and the "
                  "whole-sphere equirectangular)");
}

// cameras.txt (one camera: PINHOLE, or the COLMAP model of its lens; cx = W/2 centred) and
// images.txt (world-to-camera qvec and tvec in OpenCV axes, the image named `name`).
std::vector<CameraFileText> writeColmapModel(const Camera& camera, const std::string& name)
{
    const auto [model, params] = colmapModelOf(camera);
    std::string line =
        "1 " + std::string(model->name) + " " + std::to_string(camera.width()) + " " + std::to_string(camera.height());
    for (double value : params) line += " " + exactNumber(value);
    const glm::dmat4 m = camFromWorldIn(camera, Convention::preset("opencv"));
    const glm::dvec4 q = quaternionFromRotation(glm::dmat3(m));  // (w, x, y, z)
    const std::string cameras = "# Camera list with one line of data per camera:\n"
                                "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
                                "# Number of cameras: 1\n" + line + "\n";
    const std::string images = "# Image list with two lines of data per image:\n"
                               "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
                               "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
                               "# Number of images: 1, mean observations per image: 0\n"
                               "1 " + exactNumber(q.x) + " " + exactNumber(q.y) + " " + exactNumber(q.z) + " " + exactNumber(q.w) +
                               " " + exactNumber(m[3][0]) + " " + exactNumber(m[3][1]) + " " + exactNumber(m[3][2]) + " 1 " +
                               name + "\n\n";
    return {{"cameras.txt", cameras}, {"images.txt", images}};
}

bool detectsColmapModel(const CameraFileHead& file) { return !colmapModelFolder(file.path).empty(); }

}  // namespace

const CameraFormat& colmapFormat()
{
    static const CameraFormat row = [] {
        CameraFormat f;
        f.name = "colmap";
        f.title = "COLMAP model";
        f.extensions = {".txt", ".bin"};
        f.files = "a folder with cameras.txt and images.txt, or cameras.bin and images.bin (or one of those files)";
        f.example = "sparse/0#img_014.png";
        f.priority = 10;
        f.detects = detectsColmapModel;
        f.read = readColmapModel;
        f.input = kColmapModelInput;
        f.write = writeColmapModel;
        f.writesFolder = true;
        f.datasetSource = true;
        return f;
    }();
    return row;
}

}  // namespace zcheck::formats
