// Calibration files: OpenCV FileStorage (YAML, XML or JSON) and ROS CameraInfo (the
// camera_calibration_parsers file and the message as `topic echo` prints it).
//
// OpenCV FileStorage (docs.opencv.org, persistence.hpp; the calibration samples):
//   intrinsics  camera_matrix (or K, cameraMatrix), a 3x3 !!opencv-matrix {rows, cols, dt, data}
//               or a plain list; keys matched ignoring case (older samples wrote Camera_Matrix)
//   size        image_width, image_height (or width, height, or image_size [w, h])
//   distortion  distortion_coefficients (or D, dist_coeffs, distCoeffs, distortion), one row or
//               one column, as cv::projectPoints takes them (calib3d calibration.cpp,
//               cvProjectPoints2Internal): 4, 5, 8, 12 or 14 values k1 k2 p1 p2 [k3 [k4 k5 k6
//               [s1 s2 s3 s4 [τx τy]]]] → lens opencv, the same order; all zero (or none, or an
//               empty list) → a linear pinhole; another count is refused
//   fisheye     fisheye_model: 1 beside them (the calibration tutorial's sample,
//               samples/cpp/tutorial_code/calib3d/camera_calibration/camera_calibration.cpp,
//               saveCameraParams, writes its Calibrate_UseFisheyeModel setting as FileStorage
//               writes a bool: 0 or 1; a JSON true or false is read as 1 or 0): cv::fisheye's 4,
//               k1 k2 k3 k4 → lens opencv_fisheye, zero or not (an equidistant fisheye is no
//               pinhole); fisheye_model 1 without distortion_coefficients is refused
//   pose        optional, world-to-camera as solvePnP returns it: R (3x3, or a rotation
//               vector) and T (or t, tvec), or rvec and tvec (Rodrigues); without one the
//               camera's own frame is the world
//   views       calibration.cpp's extrinsic_parameters (a row rvec, tvec per view): cameras
//               view_0, view_1, ... beside the file's own (the default)
//   stereo      stereo_calib.cpp's intrinsics.yml: M1, D1 and M2, D2 — cameras left (alias M1)
//               and right (M2), the left the world and the right posed by stereoCalibrate's R
//               and T (x_right = R·x_left + T) from the same file or extrinsics.yml beside it;
//               extrinsics.yml alone (R, T, R1, R2, P1, P2, Q) is refused, naming the intrinsics
//   no size     the camera takes the depth map's size (K is in pixels: nothing else changes)
//   axes        OpenCV: x right, y down, z forward
//   pixels      the centre of the top-left pixel is (0, 0): a centred camera has cx = (W−1)/2
//
// ROS CameraInfo (REP 104 and the message's comments):
//   K           intrinsics of the raw (distorted) image; D its distortion by distortion_model
//               (sensor_msgs distortion_models.hpp and CameraInfo.msg; image_geometry hands D to
//               cv::projectPoints or cv::fisheye::projectPoints unchanged):
//                 plumb_bob            5: k1 k2 t1 t2 k3              → lens opencv
//                 rational_polynomial  8: k1 k2 t1 t2 k3 k4 k5 k6     → lens opencv
//                 equidistant          4: k1 k2 k3 k4 (cv::fisheye)   → lens opencv_fisheye
//               plumb_bob and rational_polynomial with D all zero (of any length, or empty, as
//               image_geometry's fromCameraInfo reads it): a linear pinhole; no
//               distortion_model key: plumb_bob (camera_calibration_parsers'
//               readCalibrationYml); an empty one with D zero or empty: a pinhole. Another
//               count, an unknown (or empty, with D not zero) name, a lens that folds: the raw
//               camera is refused (the rectified one stays)
//   P           3x4 projection of the rectified image: intrinsics fx' cx' fy' cy' and, for a
//               stereo pair's second camera, Tx = −fx'·B, Ty
//   frame       the optical frame (x right, y down, z forward) is the world: no pose
//   pixels      as OpenCV's (image_geometry wraps OpenCV)
//   cameras     "raw" (K, the default) and "rectified" (P, moved by (Tx/fx', Ty/fy', 0))
//   binning_x/y above 1 and a non-empty roi are refused (the image is not the calibrated one).
#include "formats.h"

#include "zcheck/detail/xml_lite.h"
#include "zcheck/detail/yaml_lite.h"
#include "zcheck/detail/json.h"
#include "zcheck/camera.h"
#include "zcheck/error.h"
#include "zcheck/input_file.h"
#include "zcheck/lens.h"
#include "zcheck/pose.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <optional>
#include <sstream>
#include <tuple>

namespace zcheck::formats {

const CameraFormat& opencvFormat();
const CameraFormat& rosFormat();

namespace {

using yaml::Node;

// XML and JSON documents as the YAML tree, so that one reader reads all three forms of a
// FileStorage: an element with children is a map, one with text only a scalar, type_id a tag.
Node nodeFromXml(const xml::Element& element, const std::string& source)
{
    Node node;
    node.line = element.line;
    if (const std::string* type = element.attribute("type_id")) node.tag = *type;
    if (element.children.empty()) {
        node.kind = Node::Kind::Scalar;
        node.scalar = element.text;
        return node;
    }
    // OpenCV writes a sequence's items as <_> elements; any other repeated name would let one
    // value hide another (the YAML reader refuses repeated keys too).
    const bool sequence = std::all_of(element.children.begin(), element.children.end(),
                                      [](const xml::Element& child) { return child.name == "_"; });
    node.kind = sequence ? Node::Kind::Sequence : Node::Kind::Map;
    for (const xml::Element& child : element.children) {
        if (sequence) {
            node.items.push_back(nodeFromXml(child, source));
            continue;
        }
        if (node.find(child.name))
            throw Error(source + ": line " + std::to_string(child.line) + ": the element <" + child.name +
                        "> is repeated inside <" + element.name + ">");
        node.entries.emplace_back(child.name, nodeFromXml(child, source));
    }
    return node;
}

Node nodeFromJson(const nlohmann::json& value, int depth = 0)
{
    Node node;
    if (depth > 64) throw Error("JSON nested deeper than 64 levels");
    if (value.is_object()) {
        node.kind = Node::Kind::Map;
        for (const auto& item : value.items()) {
            if (item.key() == "type_id" && item.value().is_string()) {
                node.tag = item.value().get<std::string>();
                continue;
            }
            node.entries.emplace_back(item.key(), nodeFromJson(item.value(), depth + 1));
        }
    } else if (value.is_array()) {
        node.kind = Node::Kind::Sequence;
        for (const auto& item : value) node.items.push_back(nodeFromJson(item, depth + 1));
    } else {
        node.kind = Node::Kind::Scalar;
        node.scalar = value.is_string() ? value.get<std::string>() : value.dump();
        node.quoted = value.is_string();
    }
    return node;
}

struct Matrix {
    std::size_t rows = 0, cols = 0;
    std::vector<double> values;  // row-major
    double at(std::size_t r, std::size_t c) const { return values[r * cols + c]; }
    bool allZero() const
    {
        for (double v : values)
            if (v != 0) return false;
        return true;
    }
};

bool allZero(const std::vector<double>& values)
{
    return std::all_of(values.begin(), values.end(), [](double v) { return v == 0; });
}

// A camera's lens as its file gives it: none (a linear pinhole), or a lens model of lens.h and
// its coefficients in the model's order (after fx, fy, cx, cy).
struct Distortion {
    std::string model;  // "" none, "opencv", "opencv_fisheye"
    std::vector<double> coefficients;
};

// OpenCV's counts of distortion coefficients (cvProjectPoints2Internal): k1 k2 p1 p2, then k3;
// k4 k5 k6 (CALIB_RATIONAL_MODEL); s1..s4 (CALIB_THIN_PRISM_MODEL); τx τy (CALIB_TILTED_MODEL).
constexpr std::size_t kOpenCvCounts[] = {4, 5, 8, 12, 14};
constexpr const char* kOpenCvCountRule =
    "OpenCV's calib3d takes 4, 5, 8, 12 or 14: k1 k2 p1 p2 [k3 [k4 k5 k6 [s1 s2 s3 s4 [tau_x tau_y]]]]";

class CalibrationReader {
public:
    CalibrationReader(std::string_view bytes, const std::string& path, bool ros) : path_(path), ros_(ros)
    {
        const std::string text(bytes);
        std::size_t start = text.rfind("\xEF\xBB\xBF", 0) == 0 ? 3 : 0;
        while (start < text.size() && std::isspace(static_cast<unsigned char>(text[start]))) ++start;
        if (text.compare(start, 1, "<") == 0) {
            const xml::Element root = xml::parse(text, source());
            if (root.name != "opencv_storage") fail("an XML calibration file's root element must be <opencv_storage>");
            root_ = nodeFromXml(root, source());
        } else if (text.compare(start, 1, "{") == 0) {
            try {
                root_ = nodeFromJson(parseJsonStrictly(text, source()));
            } catch (const Error& e) {
                const std::string what = e.what();
                if (what.rfind(source(), 0) == 0) throw;
                fail(what);
            }
        } else {
            root_ = yaml::parse(text, source());
        }
        if (root_.kind != Node::Kind::Map) fail("the document must be a map of keys");
    }

    CameraSet read() { return ros_ ? readRos() : readOpenCv(); }

private:
    std::string source() const { return (ros_ ? "ROS CameraInfo '" : "OpenCV calibration file '") + path_ + "'"; }
    [[noreturn]] void fail(const std::string& why) const { throw Error(source() + ": " + why); }

    // The first of `keys` present (ignoring case), or nullptr.
    const Node* anyOf(std::initializer_list<const char*> keys, std::string* found = nullptr) const
    {
        for (const char* key : keys)
            if (const Node* node = root_.findIgnoringCase(key)) {
                if (found) *found = key;
                return node;
            }
        return nullptr;
    }

    double number(const Node& node, const std::string& what) const
    {
        double value = 0;
        if (node.kind != Node::Kind::Scalar || !parseFiniteNumber(node.scalar, value))
            fail("'" + what + "' (line " + std::to_string(node.line) + ") must be a finite number");
        return value;
    }
    int pixels(const Node& node, const std::string& what) const
    {
        const double value = number(node, what);
        if (!Camera::isImageSide(value))
            fail("'" + what + "' must be a whole number of pixels in 1.." + std::to_string(Camera::kMaxImageSide) + ", got " + formatNumber(value));
        return int(value);
    }

    // A matrix's row or column count: a whole number in 0..64 (an empty D is written 1 x 0).
    std::size_t matrixSide(const Node& node, const std::string& what) const
    {
        const double value = number(node, what);
        if (!(value >= 0 && value <= 64 && value == std::floor(value)))
            fail("'" + what + "' must be a whole number of matrix rows or columns in 0..64, got " + formatNumber(value));
        return std::size_t(value);
    }

    // A matrix: {rows, cols, data} (OpenCV's !!opencv-matrix, ROS's calibration file), a flat
    // list, or a list of rows. `rows`, `cols` of 0 accept any shape.
    Matrix matrix(const Node& node, const std::string& key) const
    {
        Matrix m;
        auto numbersOf = [&](const Node& data) {
            std::vector<double> out;
            if (data.kind == Node::Kind::Scalar) {  // XML: whitespace-separated numbers
                std::istringstream in(data.scalar);
                for (std::string token; in >> token;) {
                    double v = 0;
                    if (!parseFiniteNumber(token, v)) fail("'" + key + "' holds '" + printableExcerpt(token, 30) + "', not a finite number");
                    out.push_back(v);
                }
                return out;
            }
            if (data.kind != Node::Kind::Sequence) fail("'" + key + "' data must be a list of numbers");
            for (const Node& item : data.items) out.push_back(number(item, key));
            return out;
        };
        if (node.kind == Node::Kind::Map) {
            const Node* rows = node.find("rows");
            const Node* cols = node.find("cols");
            const Node* data = node.find("data");
            if (!rows || !cols || !data) fail("'" + key + "' must have rows, cols and data");
            m.rows = matrixSide(*rows, key + ".rows");
            m.cols = matrixSide(*cols, key + ".cols");
            if (const Node* dt = node.find("dt"); dt && dt->kind == Node::Kind::Scalar) {
                const std::string type = dt->scalar;
                if (type != "d" && type != "f" && type != "i" && type != "s" && type != "w" && type != "u" && type != "c")
                    fail("'" + key + ".dt' is '" + printableExcerpt(type, 10) + "': a one-channel matrix (d, f, i, ...) is expected");
            }
            m.values = numbersOf(*data);
            if (m.values.size() != m.rows * m.cols)
                fail("'" + key + "' is " + std::to_string(m.rows) + "x" + std::to_string(m.cols) + " but its data holds " +
                     std::to_string(m.values.size()) + " numbers");
            return m;
        }
        if (node.kind == Node::Kind::Sequence && !node.items.empty() && node.items[0].kind == Node::Kind::Sequence) {
            m.rows = node.items.size();
            for (const Node& row : node.items) {
                const std::vector<double> values = numbersOf(row);
                if (m.cols == 0) m.cols = values.size();
                if (values.size() != m.cols || m.cols == 0) fail("'" + key + "' rows must all have the same number of numbers");
                m.values.insert(m.values.end(), values.begin(), values.end());
            }
            return m;
        }
        m.values = numbersOf(node);
        m.rows = 1, m.cols = m.values.size();
        return m;
    }
    Matrix shaped(const Node& node, const std::string& key, std::size_t rows, std::size_t cols) const
    {
        Matrix m = matrix(node, key);
        if (m.values.size() != rows * cols)
            fail("'" + key + "' must hold " + std::to_string(rows) + "x" + std::to_string(cols) + " numbers, it holds " +
                 std::to_string(m.values.size()));
        m.rows = rows, m.cols = cols;
        return m;
    }

    PinholeIntrinsics intrinsicsOf(const Matrix& k, const std::string& key) const
    {
        double rows[3][3];
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) rows[r][c] = k.at(std::size_t(r), std::size_t(c));
        try {
            return PinholeIntrinsics::fromK(rows, 0.0, key);
        } catch (const Error& e) {
            fail(e.what());
        }
    }

    // Distortion coefficients: one row or one column of numbers (an empty list: none).
    std::vector<double> coefficients(const Node& d, const std::string& dKey) const
    {
        const Matrix m = matrix(d, dKey);
        if (m.rows > 1 && m.cols > 1)
            fail("'" + dKey + "' is " + std::to_string(m.rows) + "x" + std::to_string(m.cols) +
                 ": distortion coefficients are one row or one column");
        return m.values;
    }

    // The camera of K and the pose, and its lens when `lens` names one (its errors, a lens that
    // folds inside the image, say, prefixed with `lensKey`): thrown, or with `refuseLens` kept as
    // the camera's refusal (a CameraInfo's raw camera: the rectified one stays usable).
    ImportedCamera camera(const std::string& name, int width, int height, const PinholeIntrinsics& k, const glm::dmat4& camFromWorld,
                          const std::string& poseName, const Distortion& lens = {}, const std::string& lensKey = "",
                          bool refuseLens = false) const
    {
        ImportedCamera out;
        out.name = name;
        const Convention opencv = Convention::preset("opencv");
        CameraSpec& spec = out.spec;
        spec.convention = opencv;
        spec.width = width, spec.height = height;
        try {
            spec.projection = k.projection(kPlaceholderNear, kPlaceholderFar, "intrinsics");
            spec.view = viewFromPose(camFromWorld, PoseDirection::CameraFromWorld, opencv, opencv, poseName);
            Camera validated(spec);
        } catch (const Error& e) {
            fail(e.what());
        }
        if (!lens.model.empty()) {
            try {
                const Projection withLens =
                    k.lensProjection(lens.model, lens.coefficients, kPlaceholderNear, kPlaceholderFar, lensKey);
                requireLens(withLens.lens, width, height);
                spec.projection = withLens;
            } catch (const Error& e) {
                const std::string why = source() + ": " + lensKey + ": " + e.what();
                if (!refuseLens) throw Error(why);
                out.refusal = why;  // the camera stays the pinhole of K
            }
        }
        return out;
    }

    // The lens validated for the image as a Camera validates it (LensModel; the rest of the
    // camera is the pinhole's, validated before), once per lens and size: calibration.cpp's
    // views share theirs.
    void requireLens(const LensSpec& lens, int width, int height) const
    {
        for (const auto& [valid, w, h] : validLenses_)
            if (valid == lens && w == width && h == height) return;
        const LensModel model(lens, width, height);
        validLenses_.emplace_back(lens, width, height);
    }

    // ---- OpenCV ---------------------------------------------------------------------

    glm::dmat3 rotationOf(const Matrix& r, const std::string& key) const
    {
        if (r.values.size() == 3) {  // a rotation vector: axis × angle (Rodrigues)
            const glm::dvec3 v(r.values[0], r.values[1], r.values[2]);
            const double angle = glm::length(v);
            if (angle == 0) return glm::dmat3(1.0);
            const glm::dvec3 axis = v / angle;
            const double s = std::sin(angle / 2);
            return rotationFromQuaternion(std::cos(angle / 2), s * axis.x, s * axis.y, s * axis.z, key);
        }
        if (r.values.size() != 9) fail("'" + key + "' must be a 3x3 rotation or a rotation vector of 3 numbers");
        glm::dmat3 m;
        for (int row = 0; row < 3; ++row)
            for (int col = 0; col < 3; ++col) m[col][row] = r.values[std::size_t(3 * row + col)];
        return m;
    }

    // The image size the file gives (image_width and image_height, width and height, or
    // image_size [w, h]); none: stereo_calib.cpp's intrinsics.yml, for one.
    std::optional<std::pair<int, int>> imageSize() const
    {
        std::string wKey, hKey;
        if (const Node* w = anyOf({"image_width", "width"}, &wKey)) {
            const Node* h = anyOf({"image_height", "height"}, &hKey);
            if (!h) fail("it gives '" + wKey + "' but no image height (image_height)");
            return std::pair{pixels(*w, wKey), pixels(*h, hKey)};
        }
        if (const Node* size = anyOf({"image_size", "imageSize"}, &wKey)) {
            const Matrix s = shaped(*size, wKey, 1, 2);
            if (!Camera::isImageSide(s.values[0]) || !Camera::isImageSide(s.values[1]))
                fail("'" + wKey + "' must be two whole numbers of pixels in 1.." + std::to_string(Camera::kMaxImageSide));
            return std::pair{int(s.values[0]), int(s.values[1])};
        }
        return std::nullopt;
    }

    // World-to-camera from a rotation (3x3 or a rotation vector) and a translation of 3.
    glm::dmat4 poseOf(const Matrix& r, const std::string& rKey, const Matrix& t, const std::string& tKey) const
    {
        if (t.values.size() != 3) fail("'" + tKey + "' must hold 3 numbers, it holds " + std::to_string(t.values.size()));
        return poseFromRotationTranslation(rotationOf(r, rKey), {t.values[0], t.values[1], t.values[2]});
    }

    // The file's R and T (or rvec and tvec), world-to-camera; none without them.
    std::optional<glm::dmat4> pose(std::string& rKey, std::string& tKey) const
    {
        const Node* r = anyOf({"R", "rvec", "rotation"}, &rKey);
        const Node* t = anyOf({"T", "t", "tvec", "translation"}, &tKey);
        if (bool(r) != bool(t)) fail("a pose needs both a rotation (R or rvec) and a translation (T or tvec)");
        if (!r) return std::nullopt;
        return poseOf(matrix(*r, rKey), rKey, matrix(*t, tKey), tKey);
    }

    // camera_calibration.cpp's fisheye_model (the file comment): whether cv::fisheye calibrated
    // the camera. FileStorage writes the bool as 0 or 1; a JSON true or false reads as 1 or 0.
    bool fisheyeModel() const
    {
        const Node* node = root_.findIgnoringCase("fisheye_model");
        if (!node) return false;
        std::string text;
        if (node->kind == Node::Kind::Scalar) {
            text = node->scalar;
            const auto space = [](unsigned char c) { return std::isspace(c) != 0; };
            while (!text.empty() && space(text.back())) text.pop_back();
            text.erase(text.begin(), std::find_if_not(text.begin(), text.end(), space));
            double value = 0;
            if (text == "true" || (parseFiniteNumber(text, value) && value == 1)) return true;
            if (text == "false" || (parseFiniteNumber(text, value) && value == 0)) return false;
        }
        fail("'fisheye_model' (line " + std::to_string(node->line) + ") must be 0 or 1 (whether cv::fisheye calibrated the camera), got " +
             (node->kind == Node::Kind::Scalar ? "'" + printableExcerpt(text, 20) + "'" : std::string("a list or map")));
    }

    // The lens of distortion coefficients `d` (the file comment's rule), and fisheye_model's.
    Distortion openCvDistortion(const Node* d, const std::string& dKey) const
    {
        const bool fisheye = fisheyeModel();
        if (!d) {
            if (fisheye)
                fail("fisheye_model is 1 but there are no distortion_coefficients: cv::fisheye takes 4 (k1, k2, k3, k4)");
            return {};
        }
        const std::vector<double> values = coefficients(*d, dKey);
        const std::size_t n = values.size();
        if (fisheye) {
            if (n != 4)
                fail("'" + dKey + "' holds " + std::to_string(n) +
                     " coefficients; with fisheye_model 1 (cv::fisheye) it takes 4: k1, k2, k3, k4");
            return {"opencv_fisheye", values};
        }
        if (n == 0) return {};  // OpenCV reads an empty distCoeffs as zeros
        if (std::find(std::begin(kOpenCvCounts), std::end(kOpenCvCounts), n) == std::end(kOpenCvCounts))
            fail("'" + dKey + "' holds " + std::to_string(n) + " coefficients; " + kOpenCvCountRule);
        if (allZero(values)) return {};
        return {"opencv", values};
    }

    // One camera of the file: K, its distortion (a lens; none when zero), the pose, and the size
    // or, without one, the depth map's (the projection does not depend on it: K is in pixels).
    ImportedCamera openCvCamera(const std::string& name, const Node& k, const std::string& kKey, const Node* d,
                                const std::string& dKey, const glm::dmat4& camFromWorld, const std::string& poseName) const
    {
        const PinholeIntrinsics intrinsics = intrinsicsOf(shaped(k, kKey, 3, 3), kKey);
        const Distortion lens = openCvDistortion(d, dKey);
        const std::optional<std::pair<int, int>> size = imageSize();
        // Without a size, a placeholder the principal point centres (a map's size replaces it).
        const int width = size ? size->first : std::clamp(int(std::lround(2 * intrinsics.cx + 1)), 1, Camera::kMaxImageSide);
        const int height = size ? size->second : std::clamp(int(std::lround(2 * intrinsics.cy + 1)), 1, Camera::kMaxImageSide);
        ImportedCamera imported = camera(name, width, height, intrinsics, camFromWorld, poseName, lens, dKey);
        if (!size) {
            imported.hasImageSize = false;
            imported.projectionForSize = [projection = imported.spec.projection](int, int) { return projection; };
        }
        return imported;
    }

    std::string fileName() const
    {
        const std::size_t slash = path_.find_last_of('/');
        return slash == std::string::npos ? path_ : path_.substr(slash + 1);
    }

    CameraSet readOpenCv() const
    {
        CameraSet set;
        set.path = path_;
        if (root_.findIgnoringCase("M1") && root_.findIgnoringCase("M2")) return readStereo(set);
        std::string kKey, dKey;
        const Node* k = anyOf({"camera_matrix", "K", "cameraMatrix", "intrinsic_matrix", "intrinsics"}, &kKey);
        if (!k && (root_.findIgnoringCase("P1") || root_.findIgnoringCase("R1") || root_.findIgnoringCase("Q")))
            fail("it holds a stereo pair's extrinsics (R, T, R1, R2, P1, P2, Q) but no camera matrix: give its intrinsics "
                 "file (stereo_calib's intrinsics.yml, M1 and M2) as FILE#left or FILE#right, which takes R and T from "
                 "this file beside it");
        if (!k) fail("it has no camera matrix (camera_matrix or K; M1 and M2 for a stereo pair)");
        const Node* d = anyOf({"distortion_coefficients", "D", "dist_coeffs", "distCoeffs", "distortion"}, &dKey);
        // The pose, world-to-camera; none: the camera's own frame is the world.
        std::string rKey, tKey;
        const std::optional<glm::dmat4> camFromWorld = pose(rKey, tKey);
        ImportedCamera imported =
            openCvCamera(fileName(), *k, kKey, d, dKey, camFromWorld.value_or(glm::dmat4(1.0)), camFromWorld ? rKey + ", " + tKey : "pose");
        if (!camFromWorld)
            imported.spec.notes.push_back(source() +
                                          " has no pose (R and T, or rvec and tvec): the camera's own frame is the world "
                                          "(x right, y down, z forward)");
        set.cameras.push_back(imported);
        // calibration.cpp's per-view poses: extrinsic_parameters, a row (rvec, tvec) per view,
        // each a camera of its own (#view_0, #view_1, ...), the file's own camera the default.
        if (const Node* views = root_.findIgnoringCase("extrinsic_parameters")) {
            const Matrix m = matrix(*views, "extrinsic_parameters");
            if (m.cols != 6) fail("'extrinsic_parameters' must have 6 columns (rvec and tvec of each view), it has " + std::to_string(m.cols));
            for (std::size_t v = 0; v < m.rows; ++v) {
                const std::string name = "view_" + std::to_string(v);
                Matrix r, t;
                r.rows = 1, r.cols = 3, t.rows = 3, t.cols = 1;
                r.values.assign(m.values.begin() + std::ptrdiff_t(6 * v), m.values.begin() + std::ptrdiff_t(6 * v + 3));
                t.values.assign(m.values.begin() + std::ptrdiff_t(6 * v + 3), m.values.begin() + std::ptrdiff_t(6 * v + 6));
                const std::string row = "extrinsic_parameters row " + std::to_string(v);
                ImportedCamera view = openCvCamera(name, *k, kKey, d, dKey, poseOf(r, row + " rvec", t, row + " tvec"), row);
                set.cameras.push_back(view);
            }
            set.defaultCamera = 0;
        }
        return set;
    }

    // stereo_calib.cpp's intrinsics file: M1, D1 (the left camera, the world) and M2, D2 (the
    // right, posed by stereoCalibrate's R and T: x_right = R·x_left + T), R and T read from this
    // file or else from extrinsics.yml beside it.
    CameraSet readStereo(CameraSet set) const
    {
        const Node* d1 = root_.findIgnoringCase("D1");
        const Node* d2 = root_.findIgnoringCase("D2");
        ImportedCamera left = openCvCamera("left", *root_.findIgnoringCase("M1"), "M1", d1, "D1", glm::dmat4(1.0), "pose");
        left.aliases = {"M1", "0"};
        left.spec.notes.push_back(source() + ": the left camera (M1) is the world (x right, y down, z forward)");
        set.cameras.push_back(left);
        std::string rKey, tKey;
        std::optional<glm::dmat4> rightFromLeft = pose(rKey, tKey);
        std::string poseSource = source();
        if (!rightFromLeft) {
            const std::string beside = (std::filesystem::path(path_).parent_path() / "extrinsics.yml").string();
            if (std::filesystem::is_regular_file(beside)) {
                const CalibrationReader extrinsics(readInputFile(beside, opencvFormat().input), beside, ros_);
                rightFromLeft = extrinsics.pose(rKey, tKey);
                poseSource = extrinsics.source();
            }
        }
        ImportedCamera right = openCvCamera("right", *root_.findIgnoringCase("M2"), "M2", d2, "D2",
                                            rightFromLeft.value_or(glm::dmat4(1.0)), rKey + ", " + tKey);
        right.aliases = {"M2", "1"};
        if (rightFromLeft) {
            right.spec.notes.push_back("the right camera (M2) posed by R and T of " + poseSource + " (x_right = R·x_left + T)");
        } else if (right.refusal.empty()) {
            right.refusal = source() + ": the right camera (M2) has no pose: neither this file nor extrinsics.yml beside it "
                                       "holds stereoCalibrate's R and T";
        }
        set.cameras.push_back(right);
        return set;
    }

    // ---- ROS --------------------------------------------------------------------------

    // D by distortion_model (the file comment's table): the lens, or with `refusal` set why the
    // raw camera cannot be used.
    Distortion rosDistortion(const Node* d, const std::string& dKey, std::string& refusal) const
    {
        struct Model {
            const char* name;
            std::size_t count;
            const char* lens;
            const char* coefficients;
        };
        static const Model models[] = {{"plumb_bob", 5, "opencv", "k1, k2, t1, t2, k3"},
                                       {"rational_polynomial", 8, "opencv", "k1, k2, t1, t2, k3, k4, k5, k6"},
                                       {"equidistant", 4, "opencv_fisheye", "k1, k2, k3, k4"}};
        const std::string known =
            "plumb_bob (5: k1, k2, t1, t2, k3), rational_polynomial (8: k1, k2, t1, t2, k3, k4, k5, k6) or equidistant "
            "(4: k1, k2, k3, k4)";
        std::string name = "plumb_bob";  // readCalibrationYml: a file without distortion_model is plumb_bob
        if (const Node* m = root_.findIgnoringCase("distortion_model")) {
            if (m->kind != Node::Kind::Scalar)
                fail("'distortion_model' (line " + std::to_string(m->line) + ") must be a name: " + known);
            name = m->scalar;
        }
        const std::vector<double> values = d ? coefficients(*d, dKey) : std::vector<double>{};
        const Model* model = nullptr;
        for (const Model& row : models)
            if (name == row.name) model = &row;
        if (!model) {
            if (name.empty() && allZero(values)) return {};  // the message's default: no model, no distortion
            refusal = source() + ": distortion_model " + (name.empty() ? "is empty" : "'" + printableExcerpt(name, 40) + "' is unknown") +
                      ": zcheck reads " + known;
            return {};
        }
        const bool fisheye = std::string(model->lens) == "opencv_fisheye";
        // image_geometry (PinholeCameraModel::fromCameraInfo): D all zero, whatever its length,
        // is no distortion. Not for the fisheye: cv::fisheye with zeros is still equidistant.
        if (!fisheye && allZero(values)) return {};
        if (values.size() != model->count) {
            refusal = source() + ": " + dKey + " holds " + std::to_string(values.size()) + " coefficients; distortion_model " +
                      model->name + " takes " + std::to_string(model->count) + " (" + model->coefficients + ")";
            return {};
        }
        return {model->lens, values};
    }

    CameraSet readRos() const
    {
        // The calibration file's keys, else the message's (ROS 1 upper case, ROS 2 lower case).
        std::string kKey, pKey, dKey, wKey, hKey;
        const Node* k = anyOf({"camera_matrix", "K"}, &kKey);
        const Node* p = anyOf({"projection_matrix", "P"}, &pKey);
        const Node* d = anyOf({"distortion_coefficients", "D"}, &dKey);
        const Node* w = anyOf({"image_width", "width"}, &wKey);
        const Node* h = anyOf({"image_height", "height"}, &hKey);
        if (!k) fail("it has no camera matrix (camera_matrix, K or k)");
        if (!w || !h) fail("it has no image size (image_width and image_height, or width and height)");
        const int width = pixels(*w, wKey), height = pixels(*h, hKey);
        const Matrix K = shaped(*k, kKey, 3, 3);

        // An uncalibrated camera (K[0] = 0, REP 104) has no intrinsics to read: both cameras are
        // kept with the refusal, before K's form is judged.
        if (K.at(0, 0) == 0) {
            CameraSet set;
            set.path = path_, set.defaultCamera = 0;
            for (const char* name : {"raw", "rectified"}) {
                ImportedCamera uncalibrated;
                uncalibrated.name = name;
                uncalibrated.refusal = source() + ": " + kKey + "[0] is 0: the camera is uncalibrated (REP 104)";
                set.cameras.push_back(uncalibrated);
            }
            return set;
        }
        std::string refusal;
        for (const char* key : {"binning_x", "binning_y"})
            if (const Node* b = root_.findIgnoringCase(key); b && number(*b, key) > 1)
                refusal = source() + ": " + key + " is " + b->scalar +
                          ": the image is binned, not the calibrated one; zcheck reads unbinned CameraInfo";
        if (const Node* roi = root_.findIgnoringCase("roi"); roi && roi->kind == Node::Kind::Map)
            for (const char* key : {"x_offset", "y_offset", "height", "width"})
                if (const Node* v = roi->find(key); v && number(*v, std::string("roi.") + key) != 0)
                    refusal = source() + ": roi." + key + " is " + v->scalar +
                              ": the image is a region of the calibrated one; zcheck reads CameraInfo without a roi";

        CameraSet set;
        set.path = path_, set.defaultCamera = 0;
        std::string unreadable;  // D that is no lens zcheck reads
        const Distortion lens = rosDistortion(d, dKey, unreadable);
        ImportedCamera raw = camera("raw", width, height, intrinsicsOf(K, kKey), glm::dmat4(1.0), "pose", lens, dKey, true);
        if (raw.refusal.empty()) raw.refusal = unreadable;
        if (!refusal.empty())
            raw.refusal = refusal;
        else if (!raw.refusal.empty())
            raw.refusal += " (a rectified image's camera is P: FILE#rectified)";
        raw.spec.notes.push_back(source() + ": the optical frame (x right, y down, z forward) is the world");
        set.cameras.push_back(raw);

        if (p) {
            const Matrix P = shaped(*p, pKey, 3, 4);
            ImportedCamera rectified;
            if (P.allZero() || P.at(0, 0) == 0) {
                rectified.name = "rectified";
                rectified.refusal = source() + ": " + pKey + " is all zero: there is no rectified camera";
            } else {
                double rows[3][3];
                for (int r = 0; r < 3; ++r)
                    for (int c = 0; c < 3; ++c) rows[r][c] = P.at(std::size_t(r), std::size_t(c));
                PinholeIntrinsics kp;
                try {
                    kp = PinholeIntrinsics::fromK(rows, 0.0, pKey);
                } catch (const Error& e) {
                    fail(e.what());
                }
                // u = (fx'·X + cx'·Z + Tx)/Z: the camera moved by Tx/fx' along x (likewise y).
                glm::dmat4 camFromWorld(1.0);
                camFromWorld[3] = glm::dvec4(P.at(0, 3) / kp.fx, P.at(1, 3) / kp.fy, 0.0, 1.0);
                rectified = camera("rectified", width, height, kp, camFromWorld, pKey);
                rectified.refusal = refusal;
                rectified.spec.notes = raw.spec.notes;
            }
            set.cameras.push_back(rectified);
        }
        if (const Node* name = root_.findIgnoringCase("camera_name"); name && name->kind == Node::Kind::Scalar)
            set.cameras[0].aliases.push_back(name->scalar);
        return set;
    }

    std::string path_;
    bool ros_;
    Node root_;
    mutable std::vector<std::tuple<LensSpec, int, int>> validLenses_;
};


std::string opencvMatrix(const char* key, int rows, int cols, const std::vector<double>& values)
{
    std::string data;
    for (double v : values) data += (data.empty() ? "" : ", ") + exactNumber(v);
    return std::string(key) + ": !!opencv-matrix\n   rows: " + std::to_string(rows) + "\n   cols: " + std::to_string(cols) +
           "\n   dt: d\n   data: [ " + data + " ]\n";
}

// The distortion coefficients OpenCV has for a camera's lens: none for a pinhole (written as
// five zeros, as calibration.cpp's files have them); lens opencv's in the shortest of OpenCV's
// counts that holds every nonzero one; opencv_fisheye's four, with `fisheye` set. Any other
// model is refused.
std::vector<double> openCvCoefficients(const Camera& camera, bool& fisheye)
{
    fisheye = false;
    const LensModel* lens = camera.lens();
    if (!lens) return {0, 0, 0, 0, 0};
    const std::string& model = lens->spec().model;
    const std::vector<double>& q = lens->spec().params;  // every parameter (LensModel writes the defaults out)
    if (model == "opencv") {
        std::size_t needed = 0;
        for (std::size_t i = 4; i < q.size(); ++i)
            if (q[i] != 0) needed = i - 3;
        const std::size_t n = *std::find_if(std::begin(kOpenCvCounts), std::end(kOpenCvCounts),
                                            [&](std::size_t count) { return count >= needed; });
        return std::vector<double>(q.begin() + 4, q.begin() + 4 + std::ptrdiff_t(n));
    }
    if (model == "opencv_fisheye") {
        fisheye = true;
        return std::vector<double>(q.begin() + 4, q.begin() + 8);
    }
    throw Error("OpenCV has no " + model + " lens model: an OpenCV calibration file holds lens opencv (calib3d's k1 k2 p1 p2 "
                "k3 ... tau_y) or opencv_fisheye (cv::fisheye's k1..k4, fisheye_model: 1)");
}

// camera.yml, FileStorage YAML: camera_matrix (cx = (W−1)/2 centred), distortion_coefficients
// (and fisheye_model: 1 for cv::fisheye's, as camera_calibration.cpp writes it), image_width,
// image_height, R and T world-to-camera.
std::vector<CameraFileText> writeOpenCv(const Camera& camera, const std::string&)
{
    bool fisheye = false;
    const std::vector<double> d = openCvCoefficients(camera, fisheye);
    const PinholeIntrinsics k = pinholeIntrinsicsOf(camera, 0.0);
    const glm::dmat4 m = camFromWorldIn(camera, Convention::preset("opencv"));
    std::vector<double> r;
    for (int row = 0; row < 3; ++row)
        for (int col = 0; col < 3; ++col) r.push_back(m[col][row]);
    return {{"camera.yml", "%YAML:1.0\n---\nimage_width: " + std::to_string(camera.width()) + "\nimage_height: " +
                               std::to_string(camera.height()) + "\n" + (fisheye ? "fisheye_model: 1\n" : "") +
                               opencvMatrix("camera_matrix", 3, 3, {k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1}) +
                               opencvMatrix("distortion_coefficients", int(d.size()), 1, d) + opencvMatrix("R", 3, 3, r) +
                               opencvMatrix("T", 3, 1, {m[3][0], m[3][1], m[3][2]})}};
}

CameraSet readOpenCv(std::string_view bytes, const std::string& path) { return CalibrationReader(bytes, path, false).read(); }
CameraSet readRos(std::string_view bytes, const std::string& path) { return CalibrationReader(bytes, path, true).read(); }

bool detectsOpenCv(const CameraFileHead& file)
{
    return file.head.substr(0, 5) == "%YAML" || (file.looksLikeXml() && file.has("<opencv_storage")) ||
           (file.looksLikeJson() && file.has("opencv-matrix") && !file.has("\"projection\""));
}

bool detectsRos(const CameraFileHead& file)
{
    if (file.looksLikeJson() || file.looksLikeXml()) return false;
    for (const char* key : {"K", "k", "P", "p", "camera_matrix", "projection_matrix"})
        if (file.hasKeyLine(key)) return true;
    return false;
}

}  // namespace

const CameraFormat& opencvFormat()
{
    static const CameraFormat row = [] {
        CameraFormat f;
        f.name = "opencv";
        f.title = "OpenCV FileStorage";
        f.extensions = {".yml", ".yaml", ".xml", ".json"};
        f.files = "YAML, XML or JSON with camera_matrix (calibration.cpp's output, stereo_calib's intrinsics.yml as "
                  "#left or #right, per-view extrinsics as #view_N)";
        f.example = "calib.yml";
        f.priority = 40;
        f.detects = detectsOpenCv;
        f.parse = readOpenCv;
        f.input = kCameraSetInput;  // a calibration's per-view extrinsics grow with its views
        f.write = writeOpenCv;
        return f;
    }();
    return row;
}

const CameraFormat& rosFormat()
{
    static const CameraFormat row = [] {
        CameraFormat f;
        f.name = "ros";
        f.title = "ROS CameraInfo";
        f.extensions = {".yaml", ".yml"};
        f.files = "camera_calibration_parsers YAML or a `topic echo` of a CameraInfo message (#raw, #rectified)";
        f.example = "camera_info.yaml#rectified";
        f.priority = 50;
        f.detects = detectsRos;
        f.parse = readRos;
        f.input = kCameraInput;
        return f;
    }();
    return row;
}

}  // namespace zcheck::formats
