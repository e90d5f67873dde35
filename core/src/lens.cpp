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

double LensModel::radialFactor(double r2) const
{
    const Terms& t = terms_;
    double n = 0, d = 0;
    for (int i = 5; i >= 0; --i) n = (n + t.numerator[i]) * r2;
    for (int i = 2; i >= 0; --i) d = (d + t.denominator[i]) * r2;
    return (1 + n) / (1 + d);
}

namespace {
// d(N/D)/d(r²).
double radialFactorSlope(const Terms& t, double r2)
{
    double n = 0, d = 0, dn = 0, dd = 0;
    for (int i = 5; i >= 0; --i) n = (n + t.numerator[i]) * r2, dn = dn * r2 + (i + 1) * t.numerator[i];
    for (int i = 2; i >= 0; --i) d = (d + t.denominator[i]) * r2, dd = dd * r2 + (i + 1) * t.denominator[i];
    return (dn * (1 + d) - (1 + n) * dd) / ((1 + d) * (1 + d));
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
    const double r2 = glm::dot(m, m), f = radialFactor(r2), slope = radialFactorSlope(terms_, r2);
    const glm::dmat2 radial(f + 2 * m.x * m.x * slope, 2 * m.x * m.y * slope, 2 * m.x * m.y * slope,
                            f + 2 * m.y * m.y * slope);
    if (terms_.tangentialAfterRadial) return (glm::dmat2(1.0) + tangentialPrismJacobian(terms_, m * f)) * radial;
    return radial + tangentialPrismJacobian(terms_, m);
}

std::optional<glm::dvec2> LensModel::undistortPlane(const glm::dvec2& target) const
{
    if (planeIsIdentity()) return target;
    const double fMax = std::max(terms_.fx, terms_.fy);
    const auto closeEnough = [&](double residual, double size) {
        return residual * fMax <= kInverseTolerancePx || residual <= 8 * std::numeric_limits<double>::epsilon() * std::max(1.0, size);
    };
    // One unknown, the radius, on [0, fieldRadius_] where the radial map increases: Newton's
    // steps kept inside the bracket (bisection when one would leave it). The answer when the
    // distortion is radial, else the start of Newton in the plane.
    const double rt = std::hypot(target.x, target.y);
    std::optional<double> radius;
    if (rt == 0) {
        radius = 0.0;
    } else {
        double lo = 0, hi = std::isfinite(fieldRadius_) ? fieldRadius_ : std::max(1.0, 2 * rt);
        while (std::isinf(fieldRadius_) && distortedRadius(hi) < rt && hi < 1e300) hi *= 2;
        if (!(distortedRadius(hi) >= rt)) {
            if (closeEnough(rt - distortedRadius(hi), rt)) radius = hi;
        } else {
            double r = std::min(rt, hi);
            for (int iteration = 0; iteration < 200; ++iteration) {
                const double g = distortedRadius(r) - rt;
                if (closeEnough(std::abs(g), rt)) break;
                (g > 0 ? hi : lo) = r;
                const double r2 = r * r, slope = radialFactor(r2) + 2 * r2 * radialFactorSlope(terms_, r2);
                double next = r - g / slope;
                if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
                if (next == r) break;
                r = next;
            }
            if (closeEnough(std::abs(distortedRadius(r) - rt), rt)) radius = r;
        }
    }
    if (planeIsRadial()) {
        if (!radius) return std::nullopt;
        return rt == 0 ? target : target * (*radius / rt);
    }
    // In the plane: Newton on the Jacobian from the radial answer, the step halved while it does
    // not reduce the residual or would leave the field's disc.
    const double start = radius ? *radius : std::min(rt, 0.99 * fieldRadius_);
    glm::dvec2 m = rt > 0 ? target * (start / rt) : target;
    glm::dvec2 error = distortPlane(m) - target;
    const double size = rt;
    for (int iteration = 0; iteration < 100; ++iteration) {
        if (closeEnough(glm::length(error), size)) break;
        const glm::dmat2 jacobian = planeJacobian(m);
        const double det = glm::determinant(jacobian);
        if (!(std::abs(det) > 0) || !std::isfinite(det)) return std::nullopt;
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
    if (!closeEnough(glm::length(error), size)) return std::nullopt;
    return m;
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
    // The whole radial map θ ↦ |m'| (profile, then N/D) increases from 0 up to the first θ where
    // it stops: scanned in steps, the end refined by bisection on the sign of its slope.
    const auto radialAt = [&](double theta) { return distortedRadius(profileRadius(theta)); };
    const auto increasingAt = [&](double theta) {
        const double h = 1e-7 * std::max(theta, 1e-3);
        const double lo = radialAt(theta - h), hi = radialAt(theta + h);
        const double rho = profileRadius(theta);
        const double d = 1 + [&] {
            double value = 0;
            for (int i = 2; i >= 0; --i) value = (value + terms_.denominator[i]) * rho * rho;
            return value;
        }();
        return std::isfinite(lo) && std::isfinite(hi) && hi > lo && d > 0;
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
    char angle[32];
    std::snprintf(angle, sizeof angle, "%.4g", fieldAngle_ * 180 / kPi);
    throw Error("lens model " + spec_.model + " folds (is no longer one-to-one) " + angle +
                "° from the axis, inside the image: pixel (" + std::to_string(int(std::floor(edge.x))) + ", " +
                std::to_string(int(std::floor(edge.y))) + ") on the principal point's " +
                (nearest < 2 ? "row" : "column") + " lies beyond it; the coefficients do not describe this image");
}

// ---- the table of pixel rays --------------------------------------------------------------

std::optional<glm::dvec3> LensModel::directionAtPixel(int col, int row) const
{
    if (col < 0 || row < 0 || col >= width_ || row >= height_) return directionFromImage({col + 0.5, row + 0.5});
    std::call_once(tableOnce_, [&] {
        table_.resize(std::size_t(width_) * height_);
        const unsigned threads = std::max(1u, std::thread::hardware_concurrency());
        std::vector<std::thread> workers;
        for (unsigned t = 0; t < threads; ++t)
            workers.emplace_back([&, t] {
                for (int r = int(t); r < height_; r += int(threads))
                    for (int c = 0; c < width_; ++c) {
                        const std::optional<glm::dvec3> d = directionFromImage({c + 0.5, r + 0.5});
                        table_[std::size_t(r) * width_ + c] = d ? *d : glm::dvec3(NAN);
                    }
            });
        for (std::thread& worker : workers) worker.join();
    });
    const glm::dvec3& d = table_[std::size_t(row) * width_ + col];
    if (std::isnan(d.x)) return std::nullopt;
    return d;
}

// ---- the whole chain ----------------------------------------------------------------------

std::optional<glm::dvec2> LensModel::imageFromDirection(const glm::dvec3& d) const
{
    const double length = glm::length(d);
    if (!(length > 0) || !std::isfinite(length)) return std::nullopt;
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
    const double lateral = std::hypot(u.x, u.y);
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

std::optional<glm::dvec3> LensModel::directionFromImage(const glm::dvec2& p) const
{
    const Terms& t = terms_;
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
    const std::optional<glm::dvec2> m = undistortPlane(md);
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
