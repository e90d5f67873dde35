#include "zcheck/lens.h"

#include "zcheck/error.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <thread>

namespace zcheck {

namespace {

constexpr double kPi = 3.14159265358979323846;
using Terms = LensModel::Terms;
using Profile = LensModel::Profile;

// A model's row: what users see (LensModelInfo) and how its parameters become the chain's terms.
struct ModelRow {
    LensModelInfo info;
    void (*terms)(const double* p, Terms& t);
};

void focal4(const double* p, Terms& t) { t.fx = p[0], t.fy = p[1], t.cx = p[2], t.cy = p[3]; }

// Metashape: f, cx, cy, b1, b2 — fx = f + b1, skew = b2 (Agisoft's "Camera models" appendix);
// its tangential pair is OpenCV's swapped: P1 goes with r² + 2x², as OpenCV's p2 does.
void metashape(const double* p, Terms& t)
{
    t.fx = p[0] + p[3], t.fy = p[0], t.cx = p[1], t.cy = p[2], t.skew = p[4];
    for (int i = 0; i < 4; ++i) t.numerator[i] = p[5 + i];
    t.p1 = p[10], t.p2 = p[9];
}

const std::vector<ModelRow>& rows()
{
    static const std::vector<ModelRow> table = {
        {{"opencv", "OpenCV calib3d: radial (rational), tangential, thin prism, tilt",
          "m = (x/z, y/z); m' = m·(1+k1r²+k2r⁴+k3r⁶)/(1+k4r²+k5r⁴+k6r⁶) + tangential(p1, p2) + prism(s1..s4), tilted by τx, τy",
          {"fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6", "s1", "s2", "s3", "s4", "tau_x", "tau_y"},
          4, true},
         [](const double* p, Terms& t) {
             focal4(p, t);
             t.profile = Profile::Perspective;
             t.numerator[0] = p[4], t.numerator[1] = p[5], t.numerator[2] = p[8];
             t.denominator[0] = p[9], t.denominator[1] = p[10], t.denominator[2] = p[11];
             t.p1 = p[6], t.p2 = p[7];
             for (int i = 0; i < 4; ++i) t.s[i] = p[12 + i];
             t.tauX = p[16], t.tauY = p[17];
         }},
        {{"brown_conrady", "Brown–Conrady: radial polynomial to r⁸, tangential (nerfstudio and instant-ngp OPENCV)",
          "m = (x/z, y/z); m' = m·(1+k1r²+k2r⁴+k3r⁶+k4r⁸) + tangential(p1, p2)",
          {"fx", "fy", "cx", "cy", "k1", "k2", "k3", "k4", "p1", "p2"}, 4, true},
         [](const double* p, Terms& t) {
             focal4(p, t);
             t.profile = Profile::Perspective;
             for (int i = 0; i < 4; ++i) t.numerator[i] = p[4 + i];
             t.p1 = p[8], t.p2 = p[9];
         }},
        {{"opencv_fisheye", "OpenCV fisheye (Kannala–Brandt)",
          "θ = angle from the axis; m = θ·(1+k1θ²+k2θ⁴+k3θ⁶+k4θ⁸)·(cos φ, sin φ)",
          {"fx", "fy", "cx", "cy", "k1", "k2", "k3", "k4"}, 4, true},
         [](const double* p, Terms& t) {
             focal4(p, t);
             t.profile = Profile::Equidistant;
             for (int i = 0; i < 4; ++i) t.numerator[i] = p[4 + i];
         }},
        {{"thin_prism_fisheye", "COLMAP THIN_PRISM_FISHEYE",
          "m = θ·(cos φ, sin φ); m' = m·(1+k1r²+k2r⁴+k3r⁶+k4r⁸) + tangential(p1, p2) + (sx1·r², sy1·r²)",
          {"fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3", "k4", "sx1", "sy1"}, 4, true},
         [](const double* p, Terms& t) {
             focal4(p, t);
             t.profile = Profile::Equidistant;
             t.numerator[0] = p[4], t.numerator[1] = p[5], t.numerator[2] = p[8], t.numerator[3] = p[9];
             t.p1 = p[6], t.p2 = p[7], t.s[0] = p[10], t.s[2] = p[11];
         }},
        {{"fisheye624", "FISHEYE624 (Aria; COLMAP RAD_TAN_THIN_PRISM_FISHEYE)",
          "m = θ·(1+k0θ²+…+k5θ¹²)·(cos φ, sin φ); m' = m + tangential(p0, p1) + prism(s0..s3), both on m",
          {"fx", "fy", "cx", "cy", "k0", "k1", "k2", "k3", "k4", "k5", "p0", "p1", "s0", "s1", "s2", "s3"}, 4, true},
         [](const double* p, Terms& t) {
             focal4(p, t);
             t.profile = Profile::Equidistant;
             for (int i = 0; i < 6; ++i) t.numerator[i] = p[4 + i];
             t.p1 = p[11], t.p2 = p[10];  // p0 goes with r² + 2x², as OpenCV's p2 does
             for (int i = 0; i < 4; ++i) t.s[i] = p[12 + i];
             t.tangentialAfterRadial = true;
         }},
        {{"fov", "FOV (Devernay–Faugeras; COLMAP FOV, Kalibr pinhole-fov)",
          "m = atan(2·tan θ·tan(ω/2))/ω·(cos φ, sin φ)", {"fx", "fy", "cx", "cy", "omega"}, 5, true},
         [](const double* p, Terms& t) {
             focal4(p, t);
             t.profile = Profile::Fov, t.profileA = p[4];
         }},
        {{"division", "division (COLMAP DIVISION)", "the ray through m is (m, 1 + k·|m|²)",
          {"fx", "fy", "cx", "cy", "k"}, 5, true},
         [](const double* p, Terms& t) {
             focal4(p, t);
             t.profile = Profile::Division, t.profileA = p[4];
         }},
        {{"unified", "unified (Mei; Kalibr omni with radtan)",
          "m = (x, y)/(z + ξ·|d|); m' = m·(1+k1r²+k2r⁴) + tangential(p1, p2)",
          {"fx", "fy", "cx", "cy", "xi", "k1", "k2", "p1", "p2"}, 5, true},
         [](const double* p, Terms& t) {
             focal4(p, t);
             t.profile = Profile::Unified, t.profileA = p[4];
             t.numerator[0] = p[5], t.numerator[1] = p[6], t.p1 = p[7], t.p2 = p[8];
         }},
        {{"eucm", "extended unified (EUCM; Khomutenko et al. 2016)",
          "m = (x, y)/(α·√(β(x²+y²)+z²) + (1−α)·z)", {"fx", "fy", "cx", "cy", "alpha", "beta"}, 6, true},
         [](const double* p, Terms& t) {
             focal4(p, t);
             t.profile = Profile::Eucm, t.profileA = p[4], t.profileB = p[5];
         }},
        {{"double_sphere", "double sphere (Usenko et al. 2018)",
          "d2 = √(x²+y²+(ξ|d|+z)²); m = (x, y)/(α·d2 + (1−α)(ξ|d|+z))", {"fx", "fy", "cx", "cy", "xi", "alpha"}, 6,
          true},
         [](const double* p, Terms& t) {
             focal4(p, t);
             t.profile = Profile::DoubleSphere, t.profileA = p[4], t.profileB = p[5];
         }},
        {{"metashape_frame", "Agisoft Metashape frame",
          "m' = m·(1+k1r²+k2r⁴+k3r⁶+k4r⁸) + (P1(r²+2x²) + 2P2xy, P2(r²+2y²) + 2P1xy); u = cx + m'x(f+b1) + m'y·b2",
          {"f", "cx", "cy", "b1", "b2", "k1", "k2", "k3", "k4", "p1", "p2"}, 3, true},
         [](const double* p, Terms& t) {
             metashape(p, t);
             t.profile = Profile::Perspective;
         }},
        {{"metashape_fisheye", "Agisoft Metashape fisheye (equidistant)",
          "m = θ·(cos φ, sin φ), then as metashape_frame", {"f", "cx", "cy", "b1", "b2", "k1", "k2", "k3", "k4", "p1", "p2"},
          3, true},
         [](const double* p, Terms& t) {
             metashape(p, t);
             t.profile = Profile::Equidistant;
             // The manual's formula (x0 = X/Z, x = x0·atan(r0)/r0) divides by Z: it defines the
             // directions up to 90° from the axis and mirrors those beyond. What Metashape does
             // past 90° is not published, so the field ends there: such pixels have no ray.
             t.fieldLimit = LensModel::kHalfPi;
         }},
        {{"equisolid", "equisolid-angle fisheye", "m = 2·sin(θ/2)·(cos φ, sin φ)", {"fx", "fy", "cx", "cy"}, 4, true},
         [](const double* p, Terms& t) {
             focal4(p, t);
             t.profile = Profile::Equisolid;
         }},
        {{"equirectangular", "equirectangular panorama",
          "longitude atan2(x, z) and latitude atan2(−y, √(x²+z²)) linear across the image's width and height",
          {"lon_min_deg", "lon_max_deg", "lat_min_deg", "lat_max_deg"}, 4, false},
         [](const double* p, Terms& t) {
             const double toRad = kPi / 180;
             t.lonMin = p[0] * toRad, t.lonMax = p[1] * toRad, t.latMin = p[2] * toRad, t.latMax = p[3] * toRad;
         }},
        // Blender Cycles 3.4's panoramic cameras (lens.h's module comment; kernel/camera/projection.h,
        // the *_to_direction functions, which are what Cycles renders). (a, b) = (x/W + shift_x − ½,
        // y/H − shift_y − ½): the offset from the image's centre in widths and heights, right and down.
        {{"blender_fisheye_equidistant", "Blender Cycles fisheye equidistant",
          "q = 2·(a, b); θ = |q|·fisheye_fov/2 toward q; no ray for |q| > 1 (an ellipse touching the borders)",
          {"fisheye_fov", "shift_x", "shift_y"}, 1, false},
         [](const double* p, Terms& t) {
             t.blender = Terms::Blender::FisheyeEquidistant;
             t.fisheyeFov = p[0], t.shiftX = p[1], t.shiftY = p[2];
         }},
        {{"blender_fisheye_equisolid", "Blender Cycles fisheye equisolid",
          "m = (a·Sw, b·Sh) mm; θ = 2·asin(|m|/(2·fisheye_lens)) toward m; no ray for |m| > 2·fisheye_lens·sin(fisheye_fov/4)",
          {"fisheye_lens", "fisheye_fov", "fitted_sensor_width", "fitted_sensor_height", "shift_x", "shift_y"}, 4, false},
         [](const double* p, Terms& t) {
             t.blender = Terms::Blender::FisheyeEquisolid;
             t.fisheyeLens = p[0], t.fisheyeFov = p[1], t.sensorWidth = p[2], t.sensorHeight = p[3];
             t.shiftX = p[4], t.shiftY = p[5];
         }},
        {{"blender_fisheye_lens_polynomial", "Blender Cycles fisheye lens polynomial",
          "m = (a·Sw, b·Sh) mm, R = |m|; θ = −(k0 + k1R + k2R² + k3R³ + k4R⁴) toward m; no ray past fisheye_fov/2",
          {"fisheye_polynomial_k0", "fisheye_polynomial_k1", "fisheye_polynomial_k2", "fisheye_polynomial_k3",
           "fisheye_polynomial_k4", "fisheye_fov", "fitted_sensor_width", "fitted_sensor_height", "shift_x", "shift_y"},
          8, false},
         [](const double* p, Terms& t) {
             t.blender = Terms::Blender::FisheyeLensPolynomial;
             for (int i = 0; i < 5; ++i) t.polynomial[i] = p[i];
             t.fisheyeFov = p[5], t.sensorWidth = p[6], t.sensorHeight = p[7], t.shiftX = p[8], t.shiftY = p[9];
         }},
        {{"blender_mirror_ball", "Blender Cycles mirror ball",
          "q = 2·(a, b); θ = 2·asin|q| toward q (the disc's rim looks straight back); no ray for |q| ≥ 1",
          {"shift_x", "shift_y"}, 0, false},
         [](const double* p, Terms& t) {
             t.blender = Terms::Blender::MirrorBall;
             t.shiftX = p[0], t.shiftY = p[1];
         }},
        {{"blender_equiangular_cubemap_face", "Blender Cycles equiangular cubemap face",
          "the ray (tan(a·π/2), tan(b·π/2), 1): a 90° × 90° face, equiangular per axis; no ray for |a| or |b| ≥ 1",
          {"shift_x", "shift_y"}, 0, false},
         [](const double* p, Terms& t) {
             t.blender = Terms::Blender::CubemapFace;
             t.shiftX = p[0], t.shiftY = p[1];
         }},
    };
    return table;
}

const ModelRow* rowNamed(const std::string& name)
{
    for (const ModelRow& row : rows())
        if (name == row.info.name) return &row;
    return nullptr;
}

// OpenCV's tilt (calib3d distortion_model.hpp, computeTiltProjectionMatrix): the sensor turned by
// τx about x, then τy about y, projected back along the turned axis.
glm::dmat3 tiltMatrix(double tauX, double tauY)
{
    const double cx = std::cos(tauX), sx = std::sin(tauX), cy = std::cos(tauY), sy = std::sin(tauY);
    // Row-major literals; glm is column-major, so build with rows and transpose.
    const glm::dmat3 rotX = glm::transpose(glm::dmat3(1, 0, 0, 0, cx, sx, 0, -sx, cx));
    const glm::dmat3 rotY = glm::transpose(glm::dmat3(cy, 0, -sy, 0, 1, 0, sy, 0, cy));
    const glm::dmat3 rotXY = rotY * rotX;
    const double r22 = rotXY[2][2], r02 = rotXY[2][0], r12 = rotXY[2][1];  // [column][row]
    const glm::dmat3 projZ = glm::transpose(glm::dmat3(r22, 0, -r02, 0, r22, -r12, 0, 0, 1));
    return projZ * rotXY;
}

}  // namespace

const std::vector<LensModelInfo>& lensModels()
{
    static const std::vector<LensModelInfo> infos = [] {
        std::vector<LensModelInfo> out;
        for (const ModelRow& row : rows()) out.push_back(row.info);
        return out;
    }();
    return infos;
}

const LensModelInfo* lensModelNamed(const std::string& name)
{
    const ModelRow* row = rowNamed(name);
    return row ? &row->info : nullptr;
}

std::string lensModelNames()
{
    std::vector<std::string> names;
    for (const ModelRow& row : rows()) names.push_back(row.info.name);
    return joinedNames(names);
}

// ---- validation ---------------------------------------------------------------------------

LensModel::LensModel(const LensSpec& spec, int width, int height) : spec_(spec), width_(width), height_(height)
{
    const ModelRow* row = rowNamed(spec.model);
    if (!row) throw Error("unknown lens model '" + spec.model + "' (expected one of " + lensModelNames() + ")");
    info_ = &row->info;
    const std::string where = "lens model " + spec.model;
    const std::size_t n = info_->params.size();
    if (spec.params.size() < std::size_t(info_->required) || spec.params.size() > n)
        throw Error(where + " takes " +
                    (std::size_t(info_->required) == n ? std::to_string(n)
                                                       : std::to_string(info_->required) + " to " + std::to_string(n)) +
                    " parameters, got " + std::to_string(spec.params.size()));
    for (std::size_t i = 0; i < spec.params.size(); ++i)
        if (!std::isfinite(spec.params[i]))
            throw Error(where + ": '" + info_->params[i] + "' must be a finite number, got " + formatNumber(spec.params[i]));
    spec_.params.resize(n, 0.0);
    row->terms(spec_.params.data(), terms_);
    if (terms_.blender != Terms::Blender::None) {
        setUpBlender();
        return;
    }
    panorama_ = !info_->hasFocal;
    const auto require = [&](bool ok, const char* param, const std::string& rule, double value) {
        if (!ok) throw Error(where + ": '" + param + "' " + rule + ", got " + formatNumber(value));
    };
    if (panorama_) {
        const double* p = spec_.params.data();
        require(p[1] > p[0], "lon_max_deg", "must be greater than lon_min_deg", p[1]);
        require(p[1] - p[0] <= 360, "lon_max_deg", "must be at most 360° beyond lon_min_deg", p[1]);
        require(p[0] >= -360 && p[1] <= 360, "lon_min_deg", "and lon_max_deg must lie in [-360, 360]", p[0]);
        require(p[2] >= -90, "lat_min_deg", "must be at least -90", p[2]);
        require(p[3] <= 90, "lat_max_deg", "must be at most 90", p[3]);
        require(p[3] > p[2], "lat_max_deg", "must be greater than lat_min_deg", p[3]);
        fieldAngle_ = kPi;
        return;
    }
    const Terms& t = terms_;
    const char* fxName = info_->params[0];
    require(t.fx > 0, fxName, "must be > 0", t.fx);
    require(t.fy > 0, info_->params[0][0] == 'f' && info_->params[1][0] == 'f' ? info_->params[1] : fxName, "must be > 0",
            t.fy);
    switch (t.profile) {
    case Profile::Fov: require(t.profileA > 0 && t.profileA < kPi, "omega", "must lie in (0, π)", t.profileA); break;
    case Profile::Unified: require(t.profileA >= 0, "xi", "must be ≥ 0", t.profileA); break;
    case Profile::Eucm:
        require(t.profileA >= 0 && t.profileA <= 1, "alpha", "must lie in [0, 1]", t.profileA);
        require(t.profileB > 0, "beta", "must be > 0", t.profileB);
        break;
    case Profile::DoubleSphere:
        require(t.profileA > -1 && t.profileA < 1, "xi", "must lie in (-1, 1)", t.profileA);
        require(t.profileB >= 0 && t.profileB <= 1, "alpha", "must lie in [0, 1]", t.profileB);
        break;
    default: break;
    }
    require(std::abs(t.tauX) < kHalfPi / 2, "tau_x", "must lie within ±π/4 (a tilt in radians)", t.tauX);
    require(std::abs(t.tauY) < kHalfPi / 2, "tau_y", "must lie within ±π/4 (a tilt in radians)", t.tauY);
    tilt_ = tiltMatrix(t.tauX, t.tauY);
    untilt_ = glm::inverse(tilt_);
    findField();
    if (std::isfinite(fieldRadius_)) fieldDistortedRadius_ = distortedRadius(fieldRadius_);
    requireNoFoldInImage();
}

std::shared_ptr<const LensModel> LensModel::shared(const LensSpec& spec, int width, int height)
{
    static std::mutex mutex;
    static std::map<std::string, std::weak_ptr<const LensModel>> made;
    std::string key = spec.model + "/" + std::to_string(width) + "x" + std::to_string(height);
    key.append(reinterpret_cast<const char*>(spec.params.data()), spec.params.size() * sizeof(double));
    std::lock_guard<std::mutex> lock(mutex);
    if (const std::shared_ptr<const LensModel> existing = made[key].lock()) return existing;
    auto lens = std::make_shared<const LensModel>(spec, width, height);
    made[key] = lens;
    if (made.size() > 256)  // forget the models nobody holds any more
        for (auto it = made.begin(); it != made.end();) it = it->second.expired() ? made.erase(it) : std::next(it);
    return lens;
}

double LensModel::param(const std::string& name) const
{
    for (std::size_t i = 0; i < info_->params.size(); ++i)
        if (name == info_->params[i]) return spec_.params[i];
    return 0;
}

// ---- the radial profile -------------------------------------------------------------------

double LensModel::profileRadius(double theta) const
{
    const double a = terms_.profileA, b = terms_.profileB;
    const double s = std::sin(theta), c = std::cos(theta);
    switch (terms_.profile) {
    case Profile::Perspective: return std::tan(theta);
    case Profile::Equidistant: return theta;
    case Profile::Equisolid: return 2 * std::sin(theta / 2);
    case Profile::Fov: return std::atan(2 * std::tan(theta) * std::tan(a / 2)) / a;
    case Profile::Division: {
        // k·ρ²·sin θ − ρ·cos θ + sin θ = 0, the root that is ρ = tan θ at k = 0 (COLMAP's form).
        const double discriminant = c * c - 4 * a * s * s;
        if (discriminant < 0) return NAN;
        return 2 * s / (c + std::sqrt(discriminant));
    }
    case Profile::Unified: return s / (c + a);
    case Profile::Eucm: return s / (a * std::sqrt(b * s * s + c * c) + (1 - a) * c);
    case Profile::DoubleSphere: {
        const double d2 = std::sqrt(s * s + (a + c) * (a + c));
        return s / (b * d2 + (1 - b) * (a + c));
    }
    }
    return NAN;
}

namespace {
// The unit-free direction (lateral, axial) through plane radius r of the closed-form inverses
// (Mei; Khomutenko et al.; Usenko et al.), or NaN where r has no ray.
glm::dvec2 unifiedRay(double xi, double r)
{
    const double r2 = r * r, root = 1 + (1 - xi * xi) * r2;
    if (root < 0) return glm::dvec2(NAN);
    const double factor = (xi + std::sqrt(root)) / (1 + r2);
    return {factor * r, factor - xi};
}
glm::dvec2 eucmRay(double alpha, double beta, double r)
{
    const double r2 = r * r, root = 1 - (2 * alpha - 1) * beta * r2;
    if (root < 0) return glm::dvec2(NAN);
    return {r, (1 - beta * alpha * alpha * r2) / (alpha * std::sqrt(root) + (1 - alpha))};
}
glm::dvec2 doubleSphereRay(double xi, double alpha, double r)
{
    const double r2 = r * r, root = 1 - (2 * alpha - 1) * r2;
    if (root < 0) return glm::dvec2(NAN);
    const double mz = (1 - alpha * alpha * r2) / (alpha * std::sqrt(root) + 1 - alpha);
    const double inner = mz * mz + (1 - xi * xi) * r2;
    if (inner < 0) return glm::dvec2(NAN);
    const double factor = (mz * xi + std::sqrt(inner)) / (mz * mz + r2);
    return {factor * r, factor * mz - xi};
}
}  // namespace

double LensModel::profileAngle(double r) const
{
    const double a = terms_.profileA, b = terms_.profileB;
    switch (terms_.profile) {
    case Profile::Perspective: return std::atan(r);
    case Profile::Equidistant: return r;
    case Profile::Equisolid: return r > 2 ? NAN : 2 * std::asin(r / 2);
    case Profile::Fov: return r * a >= kHalfPi ? NAN : std::atan(std::tan(r * a) / (2 * std::tan(a / 2)));
    case Profile::Division: return std::atan2(r, 1 + a * r * r);
    case Profile::Unified: {
        const glm::dvec2 ray = unifiedRay(a, r);
        return std::atan2(ray.x, ray.y);
    }
    case Profile::Eucm: {
        const glm::dvec2 ray = eucmRay(a, b, r);
        return std::atan2(ray.x, ray.y);
    }
    case Profile::DoubleSphere: {
        const glm::dvec2 ray = doubleSphereRay(a, b, r);
        return std::atan2(ray.x, ray.y);
    }
    }
    return NAN;
}

// ---- the plane distortion -----------------------------------------------------------------

bool LensModel::planeIsRadial() const
{
    const Terms& t = terms_;
    return t.p1 == 0 && t.p2 == 0 && t.s[0] == 0 && t.s[1] == 0 && t.s[2] == 0 && t.s[3] == 0;
}

bool LensModel::planeIsIdentity() const
{
    const Terms& t = terms_;
    if (!planeIsRadial()) return false;
    for (double a : t.numerator)
        if (a != 0) return false;
    for (double b : t.denominator)
        if (b != 0) return false;
    return true;
}

double LensModel::radialDenominator(double r2) const
{
    double d = 0;
    for (int i = 2; i >= 0; --i) d = (d + terms_.denominator[i]) * r2;
    return 1 + d;
}

double LensModel::radialFactor(double r2) const
{
    double n = 0;
    for (int i = 5; i >= 0; --i) n = (n + terms_.numerator[i]) * r2;
    return (1 + n) / radialDenominator(r2);
}

namespace {
// N/D and its slope d(N/D)/d(r²), with one division.
struct RadialFactor {
    double value, slope;
};
RadialFactor radialFactorAndSlope(const Terms& t, double r2)
{
    double n = 0, d = 0, dn = 0, dd = 0;
    for (int i = 5; i >= 0; --i) n = (n + t.numerator[i]) * r2, dn = dn * r2 + (i + 1) * t.numerator[i];
    for (int i = 2; i >= 0; --i) d = (d + t.denominator[i]) * r2, dd = dd * r2 + (i + 1) * t.denominator[i];
    const double overD = 1 / (1 + d), value = (1 + n) * overD;
    return {value, (dn - value * dd) * overD};
}

// Tangential and thin prism terms at q, and their Jacobian.
glm::dvec2 tangentialPrism(const Terms& t, const glm::dvec2& q)
{
    const double r2 = q.x * q.x + q.y * q.y;
    return {2 * t.p1 * q.x * q.y + t.p2 * (r2 + 2 * q.x * q.x) + t.s[0] * r2 + t.s[1] * r2 * r2,
            t.p1 * (r2 + 2 * q.y * q.y) + 2 * t.p2 * q.x * q.y + t.s[2] * r2 + t.s[3] * r2 * r2};
}
glm::dmat2 tangentialPrismJacobian(const Terms& t, const glm::dvec2& q)
{
    const double r2 = q.x * q.x + q.y * q.y;
    const double sx = t.s[0] + 2 * t.s[1] * r2, sy = t.s[2] + 2 * t.s[3] * r2;
    const double xx = 2 * t.p1 * q.y + 6 * t.p2 * q.x + 2 * q.x * sx;
    const double xy = 2 * t.p1 * q.x + 2 * t.p2 * q.y + 2 * q.y * sx;
    const double yx = 2 * t.p1 * q.x + 2 * t.p2 * q.y + 2 * q.x * sy;
    const double yy = 6 * t.p1 * q.y + 2 * t.p2 * q.x + 2 * q.y * sy;
    return glm::dmat2(xx, yx, xy, yy);  // columns: ∂/∂x, ∂/∂y
}
}  // namespace

glm::dvec2 LensModel::distortPlane(const glm::dvec2& m) const
{
    const glm::dvec2 radial = m * radialFactor(glm::dot(m, m));
    return radial + tangentialPrism(terms_, terms_.tangentialAfterRadial ? radial : m);
}

glm::dmat2 LensModel::planeJacobian(const glm::dvec2& m) const
{
    const double r2 = glm::dot(m, m);
    const auto [f, slope] = radialFactorAndSlope(terms_, r2);
    const glm::dmat2 radial(f + 2 * m.x * m.x * slope, 2 * m.x * m.y * slope, 2 * m.x * m.y * slope,
                            f + 2 * m.y * m.y * slope);
    if (terms_.tangentialAfterRadial) return (glm::dmat2(1.0) + tangentialPrismJacobian(terms_, m * f)) * radial;
    return radial + tangentialPrismJacobian(terms_, m);
}

std::optional<glm::dvec2> LensModel::undistortPlane(const glm::dvec2& target) const
{
    return undistortPlane(target, nullptr);
}

std::optional<glm::dvec2> LensModel::undistortPlane(const glm::dvec2& target, InverseHint* hint) const
{
    if (planeIsIdentity()) return target;
    const double fMax = std::max(terms_.fx, terms_.fy);
    const auto closeEnough = [&](double residual, double size) {
        return residual * fMax <= kInverseTolerancePx || residual <= 8 * std::numeric_limits<double>::epsilon() * std::max(1.0, size);
    };
    const double rt = std::sqrt(target.x * target.x + target.y * target.y);
    if (!std::isfinite(rt)) return std::nullopt;
    // From a neighbour's answer: radially, its radius moved by the step between the two targets'
    // radii over the radial map's slope there; in the plane, its point moved by the step between
    // the two targets scaled by its ratio of undistorted to distorted radius.
    const bool hinted = hint && hint->valid;
    const double hintRatio = hinted ? glm::length(hint->undistorted) / glm::length(hint->distorted) : 1.0;
    double slopeAtAnswer = 0;
    const auto remember = [&](const glm::dvec2& answer) {
        if (hint) hint->distorted = target, hint->undistorted = answer, hint->radialSlope = slopeAtAnswer, hint->valid = rt > 0;
        return answer;
    };
    if (hint) hint->valid = false;
    // One unknown, the radius, on [0, fieldRadius_] where the radial map increases: Newton's
    // steps kept inside the bracket (bisection when one would leave it). The answer when the
    // distortion is radial, else (without a hint) the start of Newton in the plane.
    std::optional<double> radius;
    const bool radial = planeIsRadial();
    if (rt == 0) {
        radius = 0.0;
    } else if (radial || !hinted) {
        double lo = 0, hi = std::isfinite(fieldRadius_) ? fieldRadius_ : std::max(1.0, 2 * rt);
        while (std::isinf(fieldRadius_) && distortedRadius(hi) < rt && hi < 1e300) hi *= 2;
        const double reach = std::isfinite(fieldRadius_) ? fieldDistortedRadius_ : distortedRadius(hi);
        if (!(reach >= rt)) {
            if (closeEnough(rt - reach, rt)) radius = hi;
        } else {
            double r = rt;
            if (hinted && hint->radialSlope > 0)
                r = glm::length(hint->undistorted) + (rt - glm::length(hint->distorted)) / hint->radialSlope;
            else if (hinted)
                r = rt * hintRatio;
            if (!(r > lo && r < hi)) r = std::min(rt, hi);
            for (int iteration = 0; iteration < 200; ++iteration) {
                const double r2 = r * r;
                const auto [f, slope] = radialFactorAndSlope(terms_, r2);
                const double g = r * f - rt, radialSlope = f + 2 * r2 * slope;
                if (closeEnough(std::abs(g), rt)) {
                    radius = r, slopeAtAnswer = radialSlope;
                    break;
                }
                (g > 0 ? hi : lo) = r;
                double next = r - g / radialSlope;
                if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
                if (next == r) break;
                r = next;
            }
        }
    }
    if (radial) {
        if (!radius) return std::nullopt;
        return remember(rt == 0 ? target : target * (*radius / rt));
    }
    // In the plane: Newton on the Jacobian from the hint or the radial answer, the step halved
    // while it does not reduce the residual or would leave the field's disc.
    glm::dvec2 m = target;
    if (hinted)
        m = hint->undistorted + (target - hint->distorted) * hintRatio;
    else if (rt > 0)
        m = target * ((radius ? *radius : std::min(rt, 0.99 * fieldRadius_)) / rt);
    if (!(glm::length(m) <= fieldRadius_)) m *= 0.99 * fieldRadius_ / glm::length(m);
    glm::dvec2 error = distortPlane(m) - target;
    const double size = rt;
    for (int iteration = 0; iteration < 100; ++iteration) {
        if (closeEnough(glm::length(error), size)) break;
        const glm::dmat2 jacobian = planeJacobian(m);
        const double det = glm::determinant(jacobian);
        if (!(std::abs(det) > 0) || !std::isfinite(det)) break;
        glm::dvec2 step = glm::inverse(jacobian) * error;
        bool improved = false;
        for (int halving = 0; halving < 40 && !improved; ++halving, step *= 0.5) {
            const glm::dvec2 candidate = m - step;
            if (!(glm::length(candidate) <= fieldRadius_)) continue;  // beyond the field the map folds back
            const glm::dvec2 candidateError = distortPlane(candidate) - target;
            if (glm::length(candidateError) < glm::length(error)) m = candidate, error = candidateError, improved = true;
        }
        if (!improved) break;
    }
    if (closeEnough(glm::length(error), size)) return remember(m);
    // Newton from a neighbour's answer can stall where the radial start would not (a fold
    // between them): start again without it.
    if (hinted) return undistortPlane(target, nullptr);
    return std::nullopt;
}

// ---- Blender Cycles' panoramic cameras ----------------------------------------------------
// lens.h's module comment; the formulas are Cycles 3.4's *_to_direction functions (what it
// renders), turned into zcheck's camera frame (Blender's camera space with y and z negated) and
// image (rows from the top), and their exact inverses — not Cycles 3.4's direction_to_* functions,
// which mirror the fisheyes in u.

void LensModel::setUpBlender()
{
    using Blender = Terms::Blender;
    const Terms& t = terms_;
    const std::string where = "lens model " + spec_.model;
    const auto require = [&](bool ok, const char* param, const std::string& rule, double value) {
        if (!ok) throw Error(where + ": '" + param + "' " + rule + ", got " + formatNumber(value));
    };
    const bool fisheye = t.blender == Blender::FisheyeEquidistant || t.blender == Blender::FisheyeEquisolid ||
                         t.blender == Blender::FisheyeLensPolynomial;
    // Past 2π (Blender allows 10π) the angle from the axis passes π and the rays repeat.
    if (fisheye)
        require(t.fisheyeFov > 0 && t.fisheyeFov <= 2 * kPi, "fisheye_fov", "must lie in (0, 2π] radians", t.fisheyeFov);
    if (t.blender == Blender::FisheyeEquisolid) require(t.fisheyeLens > 0, "fisheye_lens", "must be > 0 (mm)", t.fisheyeLens);
    if (t.blender == Blender::FisheyeEquisolid || t.blender == Blender::FisheyeLensPolynomial) {
        require(t.sensorWidth > 0, "fitted_sensor_width", "must be > 0 (mm)", t.sensorWidth);
        require(t.sensorHeight > 0, "fitted_sensor_height", "must be > 0 (mm)", t.sensorHeight);
    }
    // Cycles' face is tan of (u − ½)·π/2: past a shift of ½ the image reaches 90° off the axis and
    // the tangent wraps, repeating the face.
    if (t.blender == Blender::CubemapFace) {
        require(std::abs(t.shiftX) <= 0.5, "shift_x", "must lie within ±0.5 (beyond, the face's rays repeat)", t.shiftX);
        require(std::abs(t.shiftY) <= 0.5, "shift_y", "must lie within ±0.5 (beyond, the face's rays repeat)", t.shiftY);
    }
    switch (t.blender) {
    case Blender::FisheyeEquidistant: fieldAngle_ = t.fisheyeFov / 2, fieldRadius_ = 1; break;
    case Blender::FisheyeEquisolid:
        fieldAngle_ = t.fisheyeFov / 2, fieldRadius_ = 2 * t.fisheyeLens * std::sin(t.fisheyeFov / 4);
        break;
    case Blender::MirrorBall: fieldAngle_ = kPi, fieldRadius_ = 1; break;
    case Blender::CubemapFace: fieldAngle_ = kHalfPi, fieldRadius_ = INFINITY; break;
    case Blender::FisheyeLensPolynomial: {
        // θ(R) must start at or beyond the axis (k0 ≤ 0: θ(0) = −k0) and increase (k1 < 0); the
        // field is [0, R_max], R_max where θ reaches fisheye_fov/2. Scanned over [0, 2·R_image] in
        // 8192 steps (R_image: the image corner farthest from the centre), the ends refined by
        // bisection: a fold (θ' ≤ 0) before fisheye_fov/2 inside the image, or θ back within
        // fisheye_fov/2 beyond R_max inside the image, would give pixels rays the field cannot hold.
        const double half = t.fisheyeFov / 2;
        require(t.polynomial[0] <= 0, "fisheye_polynomial_k0",
                "must be ≤ 0 (θ = −k0 at the centre; a negative θ there folds the image through its axis)", t.polynomial[0]);
        require(t.polynomial[1] < 0, "fisheye_polynomial_k1", "must be < 0 (θ = −(k0 + k1·R + …) must grow from the centre)",
                t.polynomial[1]);
        require(polynomialAngle(0) < half, "fisheye_polynomial_k0", "must be > −fisheye_fov/2 (else no pixel has a ray)",
                t.polynomial[0]);
        double imageRadius = 0;
        for (const double a : {t.shiftX - 0.5, t.shiftX + 0.5})
            for (const double b : {-t.shiftY - 0.5, -t.shiftY + 0.5})
                imageRadius = std::max(imageRadius, std::hypot(a * t.sensorWidth, b * t.sensorHeight));
        const double scanEnd = 2 * imageRadius;
        constexpr int kSteps = 8192;
        double radiusMax = scanEnd;
        bool folds = false;
        double previous = 0;
        for (int i = 1; i <= kSteps; ++i) {
            const double r = scanEnd * i / kSteps;
            const bool fold = !(polynomialSlope(r) > 0), past = !(polynomialAngle(r) < half);
            if (!fold && !past) {
                previous = r;
                continue;
            }
            double lo = previous, hi = r;
            for (int k = 0; k < 80; ++k) {
                const double mid = 0.5 * (lo + hi);
                const bool stop = fold ? !(polynomialSlope(mid) > 0) : !(polynomialAngle(mid) < half);
                (stop ? hi : lo) = mid;
            }
            radiusMax = lo, folds = fold;
            break;
        }
        char at[64];
        std::snprintf(at, sizeof at, "%.6g mm", radiusMax);
        if (folds && radiusMax < imageRadius)
            throw Error(where + ": θ(R) = −(k0 + k1·R + … + k4·R⁴) stops increasing at R = " + at +
                        ", inside the image and short of fisheye_fov/2: the lens folds (its rays repeat)");
        if (!folds)
            for (int i = 1; i <= kSteps; ++i) {
                const double r = radiusMax + (imageRadius - radiusMax) * i / kSteps;
                if (r > imageRadius) break;
                if (std::abs(polynomialAngle(r)) <= half)
                    throw Error(where + ": θ(R) comes back within fisheye_fov/2 beyond its field's edge (R = " + at +
                                "), inside the image: those pixels would have rays again");
            }
        fieldRadius_ = radiusMax;
        fieldAngle_ = polynomialAngle(radiusMax);
        break;
    }
    case Blender::None: break;
    }
}

double LensModel::polynomialAngle(double r) const
{
    const double* k = terms_.polynomial;
    return -(k[0] + r * (k[1] + r * (k[2] + r * (k[3] + r * k[4]))));
}

double LensModel::polynomialSlope(double r) const
{
    const double* k = terms_.polynomial;
    return -(k[1] + r * (2 * k[2] + r * (3 * k[3] + r * 4 * k[4])));
}

std::optional<double> LensModel::polynomialRadius(double theta) const
{
    // Newton's method on θ(R) − θ, kept inside the bracket [lo, hi] that holds the root (θ increases
    // on the field): a step that would leave it bisects instead. Converged when the step left is
    // within kInverseTolerancePx (R's residual / θ' in pixels, at W/Sw and H/Sh pixels a mm) or the
    // bracket has shrunk to rounding.
    constexpr double kSlack = 1e-12;  // rad: within rounding of the field's ends counts as on them
    double lo = 0, hi = fieldRadius_;
    const double thetaLo = polynomialAngle(lo), thetaHi = polynomialAngle(hi);
    if (theta < thetaLo - kSlack || theta > thetaHi + kSlack) return std::nullopt;
    if (theta <= thetaLo) return lo;
    if (theta >= thetaHi) return hi;
    const double pxPerMm = std::max(width_ / terms_.sensorWidth, height_ / terms_.sensorHeight);
    double r = std::clamp((theta - thetaLo) / polynomialSlope(0), lo, hi);
    for (int iteration = 0; iteration < 200; ++iteration) {
        const double residual = polynomialAngle(r) - theta, slope = polynomialSlope(r);
        if (std::abs(residual) / slope * pxPerMm <= kInverseTolerancePx) return r;
        (residual > 0 ? hi : lo) = r;
        if (hi - lo <= 4 * std::numeric_limits<double>::epsilon() * hi) return r;
        double next = r - residual / slope;
        if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
        r = next;
    }
    return std::nullopt;
}

std::optional<glm::dvec2> LensModel::blenderImageFromDirection(const glm::dvec3& u) const
{
    using Blender = Terms::Blender;
    const Terms& t = terms_;
    constexpr double kSlack = 1e-12;  // rad: within rounding of the field's edge counts as on it
    const double lateral = std::hypot(u.x, u.y);
    const double theta = std::atan2(lateral, u.z);
    const glm::dvec2 toward = lateral > 0 ? glm::dvec2(u.x, u.y) / lateral : glm::dvec2(1, 0);  // (cos ψ, sin ψ)
    glm::dvec2 offset;  // (a, b)
    switch (t.blender) {
    case Blender::FisheyeEquidistant:
        if (theta > fieldAngle_ + kSlack) return std::nullopt;
        offset = toward * (theta / t.fisheyeFov);
        break;
    case Blender::FisheyeEquisolid: {
        if (theta > fieldAngle_ + kSlack) return std::nullopt;
        const double radius = 2 * t.fisheyeLens * std::sin(theta / 2);
        offset = {radius * toward.x / t.sensorWidth, radius * toward.y / t.sensorHeight};
        break;
    }
    case Blender::FisheyeLensPolynomial: {
        const std::optional<double> radius = polynomialRadius(theta);
        if (!radius || (*radius == 0 && t.polynomial[0] != 0)) return std::nullopt;
        offset = {*radius * toward.x / t.sensorWidth, *radius * toward.y / t.sensorHeight};
        break;
    }
    case Blender::MirrorBall: {
        // |q| = sin(θ/2) = lateral / (2 cos(θ/2)), and 2 cos(θ/2) = √(2(1 + z)): no trigonometry.
        const double twoCos = std::sqrt(2 * (1 + u.z));
        if (!(twoCos > 0)) return std::nullopt;  // straight back: the whole rim
        offset = glm::dvec2(u.x, u.y) * (0.5 / twoCos);
        break;
    }
    case Blender::CubemapFace:
        if (!(u.z > 0)) return std::nullopt;
        offset = glm::dvec2(std::atan2(u.x, u.z), std::atan2(u.y, u.z)) * (2 / kPi);
        break;
    case Blender::None: return std::nullopt;
    }
    return glm::dvec2((offset.x + 0.5 - t.shiftX) * width_, (offset.y + 0.5 + t.shiftY) * height_);
}

std::optional<glm::dvec3> LensModel::blenderDirectionFromImage(const glm::dvec2& p) const
{
    using Blender = Terms::Blender;
    const Terms& t = terms_;
    const glm::dvec2 offset(p.x / width_ + t.shiftX - 0.5, p.y / height_ - t.shiftY - 0.5);  // (a, b)
    // The direction at angle θ from +z toward the plane point m (≠ 0).
    const auto at = [](double theta, const glm::dvec2& m) {
        const double r = glm::length(m);
        if (r == 0) return glm::dvec3(0, 0, 1);
        return glm::dvec3(m * (std::sin(theta) / r), std::cos(theta));
    };
    switch (t.blender) {
    case Blender::FisheyeEquidistant: {
        const glm::dvec2 q = 2.0 * offset;
        const double r = glm::length(q);
        if (r > 1) return std::nullopt;
        return at(r * t.fisheyeFov / 2, q);
    }
    case Blender::FisheyeEquisolid: {
        const glm::dvec2 m(offset.x * t.sensorWidth, offset.y * t.sensorHeight);
        const double r = glm::length(m);
        if (r > fieldRadius_) return std::nullopt;
        return at(2 * std::asin(r / (2 * t.fisheyeLens)), m);
    }
    case Blender::FisheyeLensPolynomial: {
        const glm::dvec2 m(offset.x * t.sensorWidth, offset.y * t.sensorHeight);
        const double r = glm::length(m);
        // At the very centre a θ = −k0 ≠ 0 has no azimuth: no ray (Cycles divides 0 by 0 there).
        if (r > fieldRadius_ || (r == 0 && t.polynomial[0] != 0)) return std::nullopt;
        return at(polynomialAngle(r), m);
    }
    case Blender::MirrorBall: {
        // |q| = sin(θ/2): the direction (2√(1 − |q|²)·q, 1 − 2|q|²).
        const glm::dvec2 q = 2.0 * offset;
        const double s2 = glm::dot(q, q);
        if (!(s2 < 1)) return std::nullopt;
        return glm::dvec3(q * (2 * std::sqrt(1 - s2)), 1 - 2 * s2);
    }
    case Blender::CubemapFace:
        if (!(std::abs(offset.x) < 1 && std::abs(offset.y) < 1)) return std::nullopt;
        return glm::normalize(glm::dvec3(std::tan(offset.x * kPi / 2), std::tan(offset.y * kPi / 2), 1.0));
    case Blender::None: break;
    }
    return std::nullopt;
}

// ---- the valid field ----------------------------------------------------------------------

void LensModel::findField()
{
    // The profile's own end: where ρ stops being defined or increasing.
    double limit = kPi;
    switch (terms_.profile) {
    case Profile::Perspective:
    case Profile::Fov: limit = kHalfPi; break;
    case Profile::Division:
        if (terms_.profileA > 0) limit = std::atan(1 / (2 * std::sqrt(terms_.profileA)));
        break;
    case Profile::Unified: {
        const double xi = terms_.profileA;
        limit = std::acos(-std::min(xi, xi > 1 ? 1 / xi : xi));
        break;
    }
    default: break;
    }
    if (terms_.fieldLimit > 0) limit = std::min(limit, terms_.fieldLimit);
    // The whole radial map θ ↦ |m'| (profile, then N/D) increases from 0 up to the first θ where
    // it stops: scanned in steps, the end refined by bisection on the sign of its slope.
    const auto radialAt = [&](double theta) { return distortedRadius(profileRadius(theta)); };
    const auto increasingAt = [&](double theta) {
        const double h = 1e-7 * std::max(theta, 1e-3);
        const double lo = radialAt(theta - h), hi = radialAt(theta + h);
        const double rho = profileRadius(theta);
        return std::isfinite(lo) && std::isfinite(hi) && hi > lo && radialDenominator(rho * rho) > 0;
    };
    constexpr int kSteps = 4096;
    double good = 0, bad = -1, previous = 0;
    for (int i = 1; i <= kSteps; ++i) {
        const double theta = limit * i / kSteps * (1 - 1e-12);
        const double radial = radialAt(theta);
        if (!increasingAt(theta) || !(radial > previous)) {  // a pole passed between steps shows as a drop
            bad = theta;
            break;
        }
        good = theta, previous = radial;
    }
    if (bad >= 0) {
        for (int i = 0; i < 60; ++i) {
            const double mid = 0.5 * (good + bad);
            (increasingAt(mid) ? good : bad) = mid;
        }
    } else {
        good = limit;  // the profile's own end (open: θ < limit where ρ runs to infinity)
    }
    fieldAngle_ = good;
    fieldRadius_ = profileRadius(good);
    fieldEndsInFold_ = bad >= 0 && !profileEndsAt(bad);
    if (terms_.profile == Profile::Perspective && bad < 0) fieldRadius_ = INFINITY;
    // Tangential, prism: the plane map stays one-to-one while its Jacobian determinant stays
    // positive, checked on a polar sample of the disc — rings from 10⁻³ outwards, each 2 % wider,
    // out to the field's radius; the first ring where it fails refined by bisection.
    if (!planeIsRadial()) {
        const auto positiveOn = [&](double r) {
            constexpr int kSpokes = 256;
            for (int spoke = 0; spoke < kSpokes; ++spoke) {
                const double phi = 2 * kPi * spoke / kSpokes;
                if (!(glm::determinant(planeJacobian({r * std::cos(phi), r * std::sin(phi)})) > 0)) return false;
            }
            return true;
        };
        // A pinhole's plane is unbounded: scanned out to 10⁴ (89.994° off the axis), beyond which
        // no image reaches.
        const double outermost = std::min(fieldRadius_, 1e4);
        double inside = 0;
        for (double r = 1e-3; inside < outermost; r *= 1.02) {
            const double ring = std::min(r, outermost);
            if (!positiveOn(ring)) {
                double outside = ring;
                for (int i = 0; i < 40; ++i) {
                    const double mid = 0.5 * (inside + outside);
                    (positiveOn(mid) ? inside : outside) = mid;
                }
                fieldRadius_ = inside;
                fieldAngle_ = profileAngle(fieldRadius_);
                fieldEndsInFold_ = true;
                break;
            }
            inside = ring;
        }
    }
    if (!(fieldAngle_ > 0))
        throw Error("lens model " + spec_.model + ": its distortion folds at once (no pixel around the principal point has a ray)");
}

bool LensModel::profileEndsAt(double theta) const
{
    const double h = 1e-7 * std::max(theta, 1e-3);
    const double lo = profileRadius(theta - h), hi = profileRadius(theta + h);
    return !(std::isfinite(lo) && std::isfinite(hi) && hi > lo);
}

void LensModel::requireNoFoldInImage() const
{
    const double width = width_, height = height_;
    // The largest disc around the principal point inside the image must lie within the field —
    // the nearest edge along the principal point's row or column has a ray — unless the field
    // ends where the profile ends (a fisheye's circle), not in a fold.
    const glm::dvec2 centre(terms_.cx + 0.5, terms_.cy + 0.5);
    if (centre.x < 0 || centre.y < 0 || centre.x > width || centre.y > height) return;
    const double toEdge[4] = {centre.x - 0.5, width - 0.5 - centre.x, centre.y - 0.5, height - 0.5 - centre.y};
    const glm::dvec2 along[4] = {{-1, 0}, {1, 0}, {0, -1}, {0, 1}};
    int nearest = 0;
    for (int i = 1; i < 4; ++i)
        if (toEdge[i] < toEdge[nearest]) nearest = i;
    const glm::dvec2 edge = centre + toEdge[nearest] * along[nearest];
    if (directionFromImage(edge)) return;
    // Beyond the field: a fold, or the profile's end (θ at π, a fisheye past its circle)?
    if (!fieldEndsInFold_) return;
    throw Error("lens model " + spec_.model + " folds (is no longer one-to-one) " +
                fourSignificantDigits(fieldAngle_ * 180 / kPi) + "° from the axis, inside the image: pixel (" + std::to_string(int(std::floor(edge.x))) + ", " +
                std::to_string(int(std::floor(edge.y))) + ") on the principal point's " +
                (nearest < 2 ? "row" : "column") + " lies beyond it; the coefficients do not describe this image");
}

// ---- the table of pixel rays --------------------------------------------------------------

std::optional<glm::dvec3> LensModel::directionAtPixel(int col, int row) const
{
    if (col < 0 || row < 0 || col >= width_ || row >= height_) return directionFromImage({col + 0.5, row + 0.5});
    const glm::dvec3& d = pixelDirections()[std::size_t(row) * width_ + col];
    if (std::isnan(d.x)) return std::nullopt;
    return d;
}

const glm::dvec3* LensModel::pixelDirections() const
{
    std::call_once(tableOnce_, [&] {
        table_.resize(std::size_t(width_) * height_);
        const unsigned threads = std::max(1u, std::thread::hardware_concurrency());
        std::vector<std::thread> workers;
        for (unsigned t = 0; t < threads; ++t)
            workers.emplace_back([&, t] {
                for (int r = int(t); r < height_; r += int(threads)) {
                    InverseHint hint;
                    for (int c = 0; c < width_; ++c) {
                        const std::optional<glm::dvec3> d = directionFromImage({c + 0.5, r + 0.5}, &hint);
                        table_[std::size_t(r) * width_ + c] = d ? *d : glm::dvec3(NAN);
                    }
                }
            });
        for (std::thread& worker : workers) worker.join();
    });
    return table_.data();
}

// ---- the whole chain ----------------------------------------------------------------------

std::optional<glm::dvec2> LensModel::imageFromDirection(const glm::dvec3& d) const
{
    const double length = glm::length(d);
    if (!(length > 0) || !std::isfinite(length)) return std::nullopt;
    if (terms_.blender != Terms::Blender::None) return blenderImageFromDirection(d / length);
    if (panorama_) {
        const Terms& t = terms_;
        double lon = std::atan2(d.x, d.z);
        const double lat = std::atan2(-d.y, std::hypot(d.x, d.z));
        // Within rounding (10⁻¹² rad) of a range's end counts as on it.
        constexpr double kSlack = 1e-12;
        while (lon < t.lonMin - kSlack) lon += 2 * kPi;
        while (lon > t.lonMax + kSlack && lon - 2 * kPi >= t.lonMin - kSlack) lon -= 2 * kPi;
        if (lon > t.lonMax + kSlack || lat < t.latMin - kSlack || lat > t.latMax + kSlack) return std::nullopt;
        return glm::dvec2(width_ * (lon - t.lonMin) / (t.lonMax - t.lonMin), height_ * (t.latMax - lat) / (t.latMax - t.latMin));
    }
    const glm::dvec3 u = d / length;
    const double lateral = std::sqrt(u.x * u.x + u.y * u.y);  // a unit vector's: no overflow, and hypot's cost spared
    const double theta = std::atan2(lateral, u.z);
    if (theta > fieldAngle_) return std::nullopt;
    glm::dvec2 m(0.0);
    if (terms_.profile == Profile::Perspective)
        m = {d.x / d.z, d.y / d.z};  // exact, where tan θ·(cos φ, sin φ) would round twice
    else if (lateral > 0)
        m = glm::dvec2(u.x, u.y) * (profileRadius(theta) / lateral);
    glm::dvec2 md = distortPlane(m);
    if (terms_.tauX != 0 || terms_.tauY != 0) {
        const glm::dvec3 q = tilt_ * glm::dvec3(md, 1.0);
        md = glm::dvec2(q) / q.z;
    }
    const Terms& t = terms_;
    return glm::dvec2(t.fx * md.x + t.skew * md.y + t.cx + 0.5, t.fy * md.y + t.cy + 0.5);
}

double LensModel::pixelsPerRadian(const glm::dvec3& dCam) const
{
    const std::optional<glm::dvec2> centre = imageFromDirection(dCam);
    if (!centre) return 0;
    const glm::dvec3 u = glm::normalize(dCam);
    // Two unit tangents of the sphere at u, and the image's motion along each.
    const glm::dvec3 e1 = glm::normalize(std::abs(u.x) < 0.9 ? glm::cross(u, glm::dvec3(1, 0, 0)) : glm::cross(u, glm::dvec3(0, 1, 0)));
    const glm::dvec3 e2 = glm::cross(u, e1);
    constexpr double h = 1e-7;
    auto motion = [&](const glm::dvec3& e, glm::dvec2& perRadian) {
        const std::optional<glm::dvec2> ahead = imageFromDirection(u + h * e), behind = imageFromDirection(u - h * e);
        if (ahead && behind) perRadian = (*ahead - *behind) / (2 * h);
        else if (ahead || behind) perRadian = (ahead ? *ahead - *centre : *centre - *behind) / h;
        else return false;
        return true;
    };
    glm::dvec2 c1, c2;
    if (!motion(e1, c1) || !motion(e2, c2)) return 0;
    // The larger eigenvalue of JᵀJ, J = [c1 c2].
    const double g11 = glm::dot(c1, c1), g22 = glm::dot(c2, c2), g12 = glm::dot(c1, c2);
    const double half = (g11 - g22) / 2;
    return std::sqrt((g11 + g22) / 2 + std::sqrt(half * half + g12 * g12));
}

std::optional<glm::dvec3> LensModel::directionFromImage(const glm::dvec2& p) const
{
    return directionFromImage(p, nullptr);
}

std::optional<glm::dvec3> LensModel::directionFromImage(const glm::dvec2& p, InverseHint* hint) const
{
    const Terms& t = terms_;
    if (t.blender != Terms::Blender::None) return blenderDirectionFromImage(p);
    if (panorama_) {
        if (!(p.x >= 0 && p.x <= width_ && p.y >= 0 && p.y <= height_)) return std::nullopt;
        const double lon = t.lonMin + p.x / width_ * (t.lonMax - t.lonMin);
        const double lat = t.latMax - p.y / height_ * (t.latMax - t.latMin);
        return glm::dvec3(std::cos(lat) * std::sin(lon), -std::sin(lat), std::cos(lat) * std::cos(lon));
    }
    glm::dvec2 md;
    md.y = (p.y - 0.5 - t.cy) / t.fy;
    md.x = (p.x - 0.5 - t.cx - t.skew * md.y) / t.fx;
    if (t.tauX != 0 || t.tauY != 0) {
        const glm::dvec3 q = untilt_ * glm::dvec3(md, 1.0);
        md = glm::dvec2(q) / q.z;
    }
    const std::optional<glm::dvec2> m = undistortPlane(md, hint);
    if (!m) return std::nullopt;
    const double r = glm::length(*m);
    if (r > fieldRadius_) return std::nullopt;
    if (terms_.profile == Profile::Perspective) return glm::normalize(glm::dvec3(*m, 1.0));
    const double theta = profileAngle(r);
    if (!std::isfinite(theta) || theta > fieldAngle_) return std::nullopt;
    if (r == 0) return glm::dvec3(0, 0, 1);
    const double s = std::sin(theta);
    return glm::dvec3(*m * (s / r), std::cos(theta));
}

}  // namespace zcheck
