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
// Camera models: SIMPLE_PINHOLE and PINHOLE are pinholes; SIMPLE_RADIAL, RADIAL, OPENCV,
// FULL_OPENCV, FOV, SIMPLE_DIVISION, DIVISION and EUCM are pinholes when their distortion
// coefficients are all zero (EUCM: alpha = 0); the fisheye models never are (with zero
// coefficients they are still equidistant). A camera that is not a pinhole is kept with its
// refusal (camera_import.h): only the images that use it fail.
#include "formats.h"

#include "zcheck/camera.h"
#include "zcheck/error.h"
#include "zcheck/input_file.h"
#include "zcheck/large_buffer.h"
#include "zcheck/pose.h"

#include <sys/stat.h>

#include <cstdint>
#include <cstring>
#include <map>
#include <sstream>

namespace zcheck::formats {

const CameraFormat& colmapFormat();

namespace {

struct ModelInfo {
    int id;
    const char* name;
    int focals;                           // 1: f for fx and fy; 2: fx, fy
    std::vector<const char*> distortion;  // the coefficients after fx, fy, cx, cy (or f, cx, cy)
    const char* nonLinear;                // not a pinhole for any coefficients: why ("a fisheye")
};

const std::vector<ModelInfo>& models()
{
    static const std::vector<ModelInfo> table = {
        {0, "SIMPLE_PINHOLE", 1, {}, nullptr},
        {1, "PINHOLE", 2, {}, nullptr},
        {2, "SIMPLE_RADIAL", 1, {"k"}, nullptr},
        {3, "RADIAL", 1, {"k1", "k2"}, nullptr},
        {4, "OPENCV", 2, {"k1", "k2", "p1", "p2"}, nullptr},
        {5, "OPENCV_FISHEYE", 2, {"k1", "k2", "k3", "k4"}, "a fisheye (equidistant) projection"},
        {6, "FULL_OPENCV", 2, {"k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6"}, nullptr},
        {7, "FOV", 2, {"omega"}, nullptr},
        {8, "SIMPLE_RADIAL_FISHEYE", 1, {"k"}, "a fisheye (equidistant) projection"},
        {9, "RADIAL_FISHEYE", 1, {"k1", "k2"}, "a fisheye (equidistant) projection"},
        {10, "THIN_PRISM_FISHEYE", 2, {"k1", "k2", "p1", "p2", "k3", "k4", "sx1", "sy1"}, "a fisheye (equidistant) projection"},
        {11, "RAD_TAN_THIN_PRISM_FISHEYE", 2,
         {"k0", "k1", "k2", "k3", "k4", "k5", "p0", "p1", "s0", "s1", "s2", "s3"}, "a fisheye (equidistant) projection"},
        {12, "SIMPLE_DIVISION", 1, {"k"}, nullptr},
        {13, "DIVISION", 2, {"k"}, nullptr},
        {14, "SIMPLE_FISHEYE", 1, {}, "a fisheye (equidistant) projection"},
        {15, "FISHEYE", 2, {}, "a fisheye (equidistant) projection"},
        {16, "EUCM", 2, {"alpha", "beta"}, nullptr},
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

std::size_t paramCount(const ModelInfo& m) { return std::size_t(m.focals + 2) + m.distortion.size(); }

std::string modelNames()
{
    std::string out;
    for (const ModelInfo& m : models()) out += (out.empty() ? "" : ", ") + std::string(m.name);
    return out;
}

struct ColmapCamera {
    std::int64_t width = 0, height = 0;
    PinholeIntrinsics intrinsics;
    std::string refusal;  // not a pinhole
};

// A camera's intrinsics, or why they are not a pinhole's. `where` names the line or record,
// which an impossible value (a focal length ≤ 0, a principal point beyond what binary32 rays
// can hold) is refused with, whichever image uses the camera.
ColmapCamera cameraOf(const ModelInfo& model, std::int64_t width, std::int64_t height, const std::vector<double>& p,
                      const std::string& where)
{
    {
        const std::size_t f = std::size_t(model.focals);
        CameraSpec spec;
        spec.convention = Convention::preset("opencv");
        spec.width = int(width), spec.height = int(height);
        spec.view.hasMatrix = true;
        try {
            spec.projection = PinholeIntrinsics{p[0], p[f == 1 ? 0 : 1], p[f], p[f + 1], 0.5}.projection(
                kPlaceholderNear, kPlaceholderFar, "intrinsics");
            Camera validated(spec);
        } catch (const Error& e) {
            throw Error(where + ": " + e.what());
        }
    }
    ColmapCamera camera;
    camera.width = width, camera.height = height;
    const std::size_t f = std::size_t(model.focals);
    camera.intrinsics = {p[0], p[f == 1 ? 0 : 1], p[f], p[f + 1], 0.5};
    std::vector<std::pair<std::string, double>> coefficients;
    for (std::size_t i = 0; i < model.distortion.size(); ++i) coefficients.emplace_back(model.distortion[i], p[f + 2 + i]);
    if (model.nonLinear) {
        camera.refusal = where + ": camera model " + model.name + " is " + model.nonLinear +
                         ", not a pinhole: zcheck checks linear projections; undistort the depth map and give its "
                         "pinhole camera";
    } else if (std::string(model.name) == "EUCM") {
        if (p[f + 2] != 0)  // alpha = 0 makes EUCM a pinhole whatever beta is
            camera.refusal = distortionRefusal(where, model.name, {coefficients[0]});
    } else {
        camera.refusal = distortionRefusal(where, model.name, coefficients);
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
                             " parameters, the line has " + std::to_string(t.size() - 4));
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
                      ", which zcheck does not know (COLMAP's 0..16: " + modelNames() + ")");
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
            spec.projection = intrinsics.intrinsics.projection(kPlaceholderNear, kPlaceholderFar, "intrinsics");
            double departure = 0;
            const glm::dmat4 camFromWorld = poseFromRotationTranslation(
                rotationFromQuaternion(image.q[0], image.q[1], image.q[2], image.q[3], "qvec", &departure),
                {image.t[0], image.t[1], image.t[2]});
            spec.view = viewFromPose(camFromWorld, PoseDirection::CameraFromWorld, opencv, opencv, "qvec, tvec");
            spec.view.rotationDeparture = std::max(spec.view.rotationDeparture, departure);
            Camera validated(spec);
        } catch (const Error& e) {
            throw Error(image.where + ": " + e.what());
        }
        set.cameras.push_back(std::move(camera));
    }
    return set;
}

// cameras.txt (one PINHOLE camera, cx = W/2 centred) and images.txt (world-to-camera qvec and
// tvec in OpenCV axes, the image named `name`).
std::vector<CameraFileText> writeColmapModel(const Camera& camera, const std::string& name)
{
    const PinholeIntrinsics k = pinholeIntrinsicsOf(camera, 0.5);
    const glm::dmat4 m = camFromWorldIn(camera, Convention::preset("opencv"));
    const glm::dvec4 q = quaternionFromRotation(glm::dmat3(m));  // (w, x, y, z)
    const std::string cameras = "# Camera list with one line of data per camera:\n"
                                "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
                                "# Number of cameras: 1\n"
                                "1 PINHOLE " + std::to_string(camera.width()) + " " + std::to_string(camera.height()) + " " +
                                exactNumber(k.fx) + " " + exactNumber(k.fy) + " " + exactNumber(k.cx) + " " + exactNumber(k.cy) + "\n";
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
