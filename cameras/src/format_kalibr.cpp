// Kalibr's camera chain: camchain.yaml (kalibr_calibrate_cameras) and camchain-imucam.yaml
// (kalibr_calibrate_imu_camera), as Kalibr defines it (ethz-asl/kalibr 1f602274, 2024-03-08:
// kalibr_common/ConfigReader.py, aslam_cv/aslam_cameras):
//
//   cameras     the top-level keys cam0, cam1, ..., every one a camera: Kalibr counts the keys
//               (CameraChainParameters.numCameras) and reads cam0 to cam{n−1}. PyYAML writes
//               them sorted as text (cam10 before cam2); they are read by number
//   model       camera_model and intrinsics (CameraParameters.checkIntrinsics, AslamCamera):
//                 pinhole [fu, fv, pu, pv]            omni [xi, fu, fv, pu, pv]
//                 eucm    [alpha, beta, fu, fv, pu, pv]  ds  [xi, alpha, fu, fv, pu, pv]
//               Kalibr's own checks kept: omni xi ≥ 0; ds and eucm 0 ≤ alpha < 1; eucm beta ≥ 0;
//               pu, pv ≥ 0
//   distortion  distortion_model and distortion_coeffs (checkDistortion): radtan [k1, k2, p1, p2],
//               equidistant [k1, k2, k3, k4], fov [w], none [] (absent coefficients read as [])
//   size        resolution [width, height]
//   pose        none: cam0's frame is the world (noted). camN (N ≥ 1) has T_cn_cnm1, 4x4 row-major,
//               mapping points of cam(N−1)'s frame into camN's, p_cN = T_cn_cnm1·p_cN−1
//               (setExtrinsicsLastCamToHere of CameraUtils' baselines and IccCalibrator's
//               getResultBaseline(N−1, N)), so camN_from_cam0 = T_cN_cN−1 ··· T_c1_c0. Each T
//               goes through the pose rule (pose.h). A camera whose T_cn_cnm1 is missing, and
//               every camera after it, is kept with its refusal. T_cam_imu (the IMU into the
//               camera, camchain-imucam.yaml) is checked by the same rule and not used;
//               rostopic (also an alias of the frame), cam_overlaps, timeshift_cam_imu and
//               line_delay are not read
//   axes        OpenCV: x right, y down, z forward (aslam's camera frame)
//   pixels      the top-left pixel's centre is (0, 0): PinholeProjection::initializeIntrinsics
//               starts cu at (cols − 1)/2, and the corners come from OpenCV's cornerSubPix
//   units       T_cn_cnm1's translation in the calibration target's units (metres)
//
// Lens models (lens.h), each as aslam_cv's projection and distortion classes compute it:
//   pinhole + none          the linear pinhole
//   pinhole + radtan        opencv (k1, k2, p1, p2): RadialTangentialDistortion::distort, OpenCV's
//                           pairing (2·p1·x·y in x); all four 0: the linear pinhole
//   pinhole + equidistant   opencv_fisheye (k1..k4): EquidistantDistortion::distort, θ = atan(r)
//   pinhole + fov           fov (omega = w): FovDistortion::distort; Kalibr takes w in [0.5, 1.5],
//                           or |w| < 1e-16, the identity (FovDistortion::areParametersValid): the
//                           linear pinhole
//   omni + radtan | none    unified (xi, k1, k2, p1, p2): OmniProjection::euclideanToKeypoint
//                           distorts the unified plane's point x/(z + ξ|p|)
//   eucm + none             eucm (alpha, beta): ExtendedUnifiedProjection
//   ds + none               double_sphere (xi, alpha): DoubleSphereProjection
// Every other pairing is refused as AslamCamera refuses it (omni with equidistant "not yet
// supported"; eucm and ds take no distortion model but none).
//
// No writer: a camchain has no world pose, so a posed camera written there would not read back
// as itself.
#include "formats.h"

#include "zcheck/detail/yaml_lite.h"
#include "zcheck/camera.h"
#include "zcheck/error.h"
#include "zcheck/pose.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <tuple>

namespace zcheck::formats {

const CameraFormat& kalibrFormat();

namespace {

using yaml::Node;

// A camera_model: its intrinsics' order and how many of them are its shape before fu, fv, pu, pv.
struct KalibrModel {
    const char* name;
    const char* order;
    std::size_t shapeCount;
};

const KalibrModel kModels[] = {
    {"pinhole", "[fu, fv, pu, pv]", 0},
    {"omni", "[xi, fu, fv, pu, pv]", 1},
    {"eucm", "[alpha, beta, fu, fv, pu, pv]", 2},
    {"ds", "[xi, alpha, fu, fv, pu, pv]", 2},
};

struct KalibrDistortion {
    const char* name;
    const char* order;
    std::size_t count;
};

const KalibrDistortion kDistortions[] = {
    {"radtan", "[k1, k2, p1, p2]", 4},
    {"equidistant", "[k1, k2, k3, k4]", 4},
    {"fov", "[w]", 1},
    {"none", "[]", 0},
};

// What a camera's camera_model and distortion_model are in zcheck: a lens model with its
// coefficients after fx, fy, cx, cy, or "" for the linear pinhole.
struct LensChoice {
    std::string model;
    std::vector<double> coefficients;
};

bool allZero(const std::vector<double>& values)
{
    return std::all_of(values.begin(), values.end(), [](double v) { return v == 0; });
}

class CamchainReader {
public:
    CamchainReader(std::string_view bytes, const std::string& path) : path_(path), root_(yaml::parse(bytes, source()))
    {
        if (root_.kind != Node::Kind::Map) fail(root_.line, "the document must be a map of cameras cam0, cam1, ...");
    }

    CameraSet read() const
    {
        CameraSet set;
        set.path = path_;
        std::optional<RigidTransform> camFromWorld = RigidTransform{};  // cam0's: the identity
        std::string brokenAt;  // the first camera without T_cn_cnm1: those after it cannot be placed
        const std::vector<const Node*> cameras = camerasInOrder();
        for (std::size_t n = 0; n < cameras.size(); ++n)
            set.cameras.push_back(camera(n, *cameras[n], camFromWorld, brokenAt));
        return set;
    }

private:
    std::string source() const { return "Kalibr camchain '" + path_ + "'"; }
    [[noreturn]] void fail(int line, const std::string& why) const
    {
        throw Error(source() + ": line " + std::to_string(line) + ": " + why);
    }

    static std::string nameOf(std::size_t n) { return "cam" + std::to_string(n); }

    // The cameras by number; every top-level key must be camN and the numbers 0..n−1.
    std::vector<const Node*> camerasInOrder() const
    {
        const std::size_t count = root_.entries.size();
        std::vector<const Node*> out(count, nullptr);
        for (const auto& [key, value] : root_.entries) {
            const std::string digits = key.rfind("cam", 0) == 0 ? key.substr(3) : "";
            const bool number = !digits.empty() && digits.size() <= 6 && (digits == "0" || digits[0] != '0') &&
                                std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; });
            if (!number)
                fail(value.line, "the top-level key '" + printableExcerpt(key, 40) +
                                     "' is not a camera cam0, cam1, ...: Kalibr reads every top-level key of a camchain "
                                     "as a camera (ConfigReader.py, CameraChainParameters)");
            const std::size_t n = std::stoul(digits);
            if (n >= count)
                fail(value.line, "'" + key + "' in a chain of " + std::to_string(count) +
                                     " cameras: Kalibr numbers them cam0 to " + nameOf(count - 1) + " and reads no other");
            if (value.kind != Node::Kind::Map) fail(value.line, "'" + key + "' must be a map of the camera's keys");
            out[n] = &value;  // count distinct numbers below count: each of 0..count−1 once
        }
        return out;
    }

    const Node& required(const Node& camera, const std::string& name, const char* key, const char* what) const
    {
        const Node* node = camera.find(key);
        if (!node) fail(camera.line, name + " has no '" + key + "' (" + what + "), which Kalibr requires");
        return *node;
    }

    std::string scalarOf(const Node& node, const std::string& what) const
    {
        if (node.kind != Node::Kind::Scalar || node.scalar.empty()) fail(node.line, "'" + what + "' must be a name");
        return node.scalar;
    }

    double number(const Node& node, const std::string& what) const
    {
        double value = 0;
        if (node.kind == Node::Kind::Scalar && !node.quoted && parseFiniteNumber(node.scalar, value)) return value;
        const std::string found = node.kind == Node::Kind::Scalar ? "'" + printableExcerpt(node.scalar, 30) + "'"
                                  : node.kind == Node::Kind::Map  ? "a map"
                                                                  : "a list";
        fail(node.line, "'" + what + "' must hold finite numbers, found " + found);
    }

    std::vector<double> numbers(const Node& node, const std::string& what) const
    {
        if (node.kind != Node::Kind::Sequence) fail(node.line, "'" + what + "' must be a list of numbers");
        std::vector<double> out;
        for (const Node& item : node.items) out.push_back(number(item, what));
        return out;
    }

    // A 4x4 matrix as Kalibr writes one (sm.Transformation.T().tolist()): 4 rows of 4 numbers.
    glm::dmat4 matrix4(const Node& node, const std::string& what) const
    {
        const std::string rule = "'" + what + "' must be a 4x4 matrix: a list of 4 rows of 4 numbers";
        if (node.kind != Node::Kind::Sequence || node.items.size() != 4) fail(node.line, rule);
        glm::dmat4 m(1.0);
        for (int row = 0; row < 4; ++row) {
            const Node& items = node.items[std::size_t(row)];
            if (items.kind != Node::Kind::Sequence) fail(items.line, rule);
            const std::vector<double> values = numbers(items, what);
            if (values.size() != 4) fail(items.line, rule);
            for (int col = 0; col < 4; ++col) m[col][row] = values[std::size_t(col)];
        }
        return m;
    }

    RigidTransform rigid(const Node& node, const std::string& what) const
    {
        const glm::dmat4 m = matrix4(node, what);
        try {
            return requireRigid(m, +1, what);
        } catch (const Error& e) {
            fail(node.line, e.what());
        }
    }

    std::pair<int, int> resolution(const Node& node, const std::string& what) const
    {
        const std::vector<double> wh = numbers(node, what);
        if (wh.size() != 2 || !Camera::isImageSide(wh[0]) || !Camera::isImageSide(wh[1]))
            fail(node.line, "'" + what + "' must be [width, height], two whole numbers of pixels in 1.." +
                                std::to_string(Camera::kMaxImageSide));
        return {int(wh[0]), int(wh[1])};
    }

    const KalibrModel& modelOf(const Node& node, const std::string& what) const
    {
        const std::string name = scalarOf(node, what);
        for (const KalibrModel& model : kModels)
            if (name == model.name) return model;
        fail(node.line, "'" + what + "' is '" + printableExcerpt(name, 30) +
                            "', not one of Kalibr's camera models (pinhole, omni, eucm, ds)");
    }

    const KalibrDistortion& distortionOf(const Node& node, const std::string& what) const
    {
        const std::string name = scalarOf(node, what);
        for (const KalibrDistortion& distortion : kDistortions)
            if (name == distortion.name) return distortion;
        fail(node.line, "'" + what + "' is '" + printableExcerpt(name, 30) +
                            "', not one of Kalibr's distortion models (radtan, equidistant, fov, none)");
    }

    // Kalibr's checkIntrinsics on the shape parameters and the principal point.
    void checkIntrinsics(const KalibrModel& model, const std::vector<double>& v, const Node& node,
                         const std::string& what) const
    {
        const std::string kind = model.name;
        const auto refuse = [&](const std::string& rule) {
            fail(node.line, "'" + what + "': " + rule + " (Kalibr's checkIntrinsics)");
        };
        if (kind == "omni" && v[0] < 0) refuse("xi is " + formatNumber(v[0]) + "; omni takes xi ≥ 0");
        if ((kind == "ds" && !(v[1] >= 0 && v[1] < 1)) || (kind == "eucm" && !(v[0] >= 0 && v[0] < 1)))
            refuse("alpha is " + formatNumber(kind == "ds" ? v[1] : v[0]) + "; " + kind + " takes 0 ≤ alpha < 1");
        if (kind == "eucm" && v[1] < 0) refuse("beta is " + formatNumber(v[1]) + "; eucm takes beta ≥ 0");
        const double pu = v[model.shapeCount + 2], pv = v[model.shapeCount + 3];
        if (pu < 0 || pv < 0)
            refuse("the principal point (" + formatNumber(pu) + ", " + formatNumber(pv) + ") must not be negative");
    }

    // The lens model of camera_model + distortion_model (module comment), or the refusal of a
    // pairing Kalibr does not build.
    LensChoice lensOf(const KalibrModel& model, const std::vector<double>& shape, const KalibrDistortion& distortion,
                      const std::vector<double>& d, const Node& at, const std::string& name) const
    {
        const std::string kind = model.name, dist = distortion.name;
        if (kind == "pinhole") {
            if (dist == "radtan") return allZero(d) ? LensChoice{} : LensChoice{"opencv", d};
            if (dist == "equidistant") return {"opencv_fisheye", d};
            if (dist == "fov") {
                if (std::abs(d[0]) < 1e-16) return {};
                if (!(d[0] >= 0.5 && d[0] <= 1.5))
                    fail(at.line, "'" + name + ".distortion_coeffs' w is " + formatNumber(d[0]) +
                                      ": Kalibr's fov distortion takes w in [0.5, 1.5], or 0 "
                                      "(FovDistortion::areParametersValid)");
                return {"fov", d};
            }
            return {};
        }
        if (kind == "omni" && (dist == "radtan" || dist == "none")) {
            std::vector<double> coefficients = shape;
            coefficients.insert(coefficients.end(), d.begin(), d.end());
            return {"unified", coefficients};
        }
        if (kind == "eucm" && dist == "none") return {"eucm", shape};
        if (kind == "ds" && dist == "none") return {"double_sphere", shape};
        fail(at.line, name + ": camera_model " + kind + " with distortion_model " + dist +
                          " is not a camera Kalibr builds (AslamCamera: pinhole takes radtan, equidistant, fov or none; "
                          "omni radtan or none; eucm and ds none)");
    }

    Projection projectionOf(const Node& camera, const std::string& name) const
    {
        const KalibrModel& model =
            modelOf(required(camera, name, "camera_model", "pinhole, omni, eucm or ds"), name + ".camera_model");
        const Node& intrinsicsNode = required(camera, name, "intrinsics", model.order);
        const std::vector<double> v = numbers(intrinsicsNode, name + ".intrinsics");
        if (v.size() != model.shapeCount + 4)
            fail(intrinsicsNode.line, "'" + name + ".intrinsics' holds " + std::to_string(v.size()) + " numbers; " +
                                          model.name + " takes " + std::to_string(model.shapeCount + 4) + ": " +
                                          model.order);
        checkIntrinsics(model, v, intrinsicsNode, name + ".intrinsics");
        const KalibrDistortion& distortion = distortionOf(
            required(camera, name, "distortion_model", "radtan, equidistant, fov or none"), name + ".distortion_model");
        std::vector<double> d;
        if (const Node* coefficients = camera.find("distortion_coeffs")) {
            d = numbers(*coefficients, name + ".distortion_coeffs");
        } else if (distortion.count != 0) {
            fail(camera.line, name + " has no 'distortion_coeffs' (" + distortion.name + ": " + distortion.order +
                                  "), which Kalibr requires");
        }
        const Node& at = camera.find("distortion_coeffs") ? *camera.find("distortion_coeffs") : camera;
        if (d.size() != distortion.count)
            fail(at.line, "'" + name + ".distortion_coeffs' holds " + std::to_string(d.size()) + " numbers; " +
                              distortion.name + " takes " + std::to_string(distortion.count) + ": " + distortion.order);
        const std::vector<double> shape(v.begin(), v.begin() + std::ptrdiff_t(model.shapeCount));
        const LensChoice lens = lensOf(model, shape, distortion, d, at, name);
        const std::size_t f = model.shapeCount;
        const PinholeIntrinsics k{v[f], v[f + 1], v[f + 2], v[f + 3], 0.0};
        const std::string what = "'" + name + ".intrinsics'";
        try {
            return lens.model.empty()
                       ? k.projection(kPlaceholderNear, kPlaceholderFar, what)
                       : k.lensProjection(lens.model, lens.coefficients, kPlaceholderNear, kPlaceholderFar, what);
        } catch (const Error& e) {
            fail(intrinsicsNode.line, e.what());
        }
    }

    // camN's pose: cam(N−1)'s taken on by T_cn_cnm1. `camFromWorld` is empty once a camera of the
    // chain has no T_cn_cnm1 (`brokenAt` names it); the cameras from there on keep a refusal.
    std::string advancePose(std::size_t n, const Node& camera, std::optional<RigidTransform>& camFromWorld,
                            std::string& brokenAt) const
    {
        const std::string name = nameOf(n);
        const Node* t = camera.find("T_cn_cnm1");
        if (n == 0) {
            if (t && rigid(*t, "cam0.T_cn_cnm1").matrix != glm::dmat4(1.0))
                fail(t->line, "'cam0.T_cn_cnm1' is not the identity: cam0 is the chain's base and has no camera before it "
                              "(Kalibr never reads it); remove it");
            return "";
        }
        if (!t && brokenAt.empty()) brokenAt = name;
        if (!brokenAt.empty()) {
            camFromWorld.reset();
            if (t) (void)rigid(*t, name + ".T_cn_cnm1");  // still bad input when it is malformed
            if (brokenAt != name)
                return source() + ": " + name + " is placed through " + brokenAt + ", which has no T_cn_cnm1";
            return source() + ": " + name + " has no T_cn_cnm1 (its pose from " + nameOf(n - 1) +
                   "), which Kalibr requires of every camera after cam0";
        }
        const RigidTransform step = rigid(*t, name + ".T_cn_cnm1");
        camFromWorld->matrix = step.matrix * camFromWorld->matrix;
        camFromWorld->departure = std::max(camFromWorld->departure, step.departure);
        return "";
    }

    ImportedCamera camera(std::size_t n, const Node& node, std::optional<RigidTransform>& camFromWorld,
                          std::string& brokenAt) const
    {
        ImportedCamera out;
        const std::string name = nameOf(n);
        out.name = name;
        if (const Node* topic = node.find("rostopic"); topic && topic->kind == Node::Kind::Scalar && !topic->scalar.empty())
            out.aliases.push_back(topic->scalar);
        if (const Node* imu = node.find("T_cam_imu")) (void)rigid(*imu, name + ".T_cam_imu");
        out.refusal = advancePose(n, node, camFromWorld, brokenAt);
        const Convention opencv = Convention::preset("opencv");
        CameraSpec& spec = out.spec;
        spec.convention = opencv;
        std::tie(spec.width, spec.height) =
            resolution(required(node, name, "resolution", "[width, height]"), name + ".resolution");
        try {
            spec.projection = projectionOf(node, name);
            const glm::dmat4 pose = camFromWorld ? camFromWorld->matrix : glm::dmat4(1.0);
            spec.view = viewFromPose(pose, PoseDirection::CameraFromWorld, opencv, opencv,
                                     n == 0 ? "pose" : "T_cn_cnm1 of cam1 to " + name);
            if (camFromWorld) spec.view.rotationDeparture = std::max(spec.view.rotationDeparture, camFromWorld->departure);
            Camera validated(spec);
        } catch (const Error& e) {
            const std::string what = e.what();
            if (what.rfind(source(), 0) == 0) throw;
            fail(node.line, name + ": " + what);
        }
        if (n == 0)
            spec.notes.push_back(source() + ": Kalibr gives no world pose: cam0's frame is the world (x right, y down, "
                                            "z forward)");
        else
            spec.notes.push_back(source() + ": " + name + " is placed in cam0's frame (the world) by T_cn_cnm1 of cam1 to " +
                                 name + " (p_camN = T_cn_cnm1·p_camN−1)");
        return out;
    }

    std::string path_;
    Node root_;
};

CameraSet readKalibr(std::string_view bytes, const std::string& path) { return CamchainReader(bytes, path).read(); }

bool detectsKalibr(const CameraFileHead& file)
{
    return !file.looksLikeJson() && !file.looksLikeXml() && file.hasKeyLine("cam0") && file.has("camera_model");
}

}  // namespace

const CameraFormat& kalibrFormat()
{
    static const CameraFormat row = [] {
        CameraFormat f;
        f.name = "kalibr";
        f.aliases = {"camchain"};
        f.title = "Kalibr camchain";
        f.extensions = {".yaml"};
        f.files = "Kalibr's camchain.yaml or camchain-imucam.yaml: cameras cam0, cam1, ... (pinhole, omni, eucm, ds), cam0 "
                  "the world, each next camera placed by its T_cn_cnm1";
        f.example = "camchain.yaml#cam1";
        f.priority = 60;
        f.detects = detectsKalibr;
        f.parse = readKalibr;
        f.input = kCameraInput;
        return f;
    }();
    return row;
}

}  // namespace zcheck::formats
