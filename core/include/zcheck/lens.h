#pragma once
// Lens models: central cameras whose projection is not linear — lens distortion, fisheyes,
// panoramas. One model, written once; every importer, the rays, verify, export, unproject,
// remap, the writers and Python use it.
//
// Spaces
//   camera frame — OpenCV's and COLMAP's: x right, y down, z forward (Camera turns a
//                  convention's eye space into it: x, −eyeUpY·y, eyeForwardZ·z)
//   image        — zcheck's image coordinates (camera.h): x from the left edge, y from the top
//                  edge, pixel (col,row) centred at (col + ½, row + ½)
//   cx, cy       — a model's principal point is OpenCV's pixel coordinates, where the centre of
//                  the top-left pixel is (0,0), as the pinhole projection's is. Importers of
//                  formats that count from the corner (COLMAP, nerfstudio) subtract ½.
//
// Every radially symmetric model is one chain, each stage written once:
//   direction d (unit)  → θ = angle from +z, φ = atan2(d.y, d.x)
//   radial profile      m = ρ(θ)·(cos φ, sin φ)          ρ: tan θ, θ, 2 sin(θ/2), FOV, division,
//                                                         unified, EUCM, double sphere
//   plane distortion    m' = m·N(r²)/D(r²) + T(m) + S(r²), r = |m|   (N up to r¹², D up to r⁶,
//                       T tangential, S thin prism; T and S on m·N/D for FISHEYE624), then
//                       OpenCV's tilt (τx, τy)
//   affine              u = fx·m'x + skew·m'y + cx,  v = fy·m'y + cy,  image = (u + ½, v + ½)
// The equirectangular panorama maps longitude atan2(d.x, d.z) and latitude atan2(−d.y,
// hypot(d.x, d.z)) linearly onto the image instead.
//
// Inverse: the profile's inverse in closed form (atan, asin, Mei's, Khomutenko's, Usenko's);
// the plane distortion's by Newton's method on its own Jacobian — on the radius alone when it
// is purely radial (bracketed, so it cannot leave the valid interval), in the plane otherwise.
// Convergence test: the forward map of the result lands within kInverseTolerancePx of the pixel.
//
// Valid field: the directions within θ ≤ fieldAngle() — where the profile is defined and the
// whole chain is one-to-one (the radial map r ↦ |m'| increases, the plane distortion's Jacobian
// determinant stays positive on a polar sample of the disc) — and for the panorama its longitude
// and latitude ranges. Outside it a pixel has no ray and a direction no pixel: their own class,
// never a garbage ray. A lens that folds before reaching the image's edge along the principal
// point's row or column is refused when the camera is built.
//
// Blender Cycles' panoramic cameras (3.4; the blender_* models) are a branch of their own, not the
// chain: Blender normalises the image by its width and height, not by a focal length. With x, y an
// image point, W × H the image, the offset from the image's centre in widths and heights (right,
// down) is (a, b) = (x/W + shift_x − ½, y/H − shift_y − ½) — Blender's (u − ½, ½ − v), its shift
// in whole widths and heights — and each model maps (a, b) to a direction at angle θ from +z
// toward (a, b) (scaled per axis where it says so): fisheye equidistant q = 2(a, b), θ =
// |q|·fisheye_fov/2, no ray for |q| > 1 (an ellipse touching the borders when W ≠ H); fisheye
// equisolid m = (a·Sw, b·Sh) mm, θ = 2·asin(|m|/2f), no ray for |m| > 2f·sin(fisheye_fov/4);
// fisheye lens polynomial m as equisolid, θ = −(k0 + k1|m| + … + k4|m|⁴), no ray past fisheye_fov/2;
// mirror ball q = 2(a, b), |q| = sin(θ/2), no ray for |q| ≥ 1; equiangular cubemap face (tan(aπ/2),
// tan(bπ/2), 1), no ray for |a| or |b| ≥ 1. Every inverse is closed form but the polynomial's,
// Newton's method on the radius bracketed by its field (convergence: within kInverseTolerancePx).
// The equirectangular panorama is Blender's too, its ranges moved by the shift (zcheck.blender).
//
// Models are data: lensModels() lists them with their parameters in order; a model's
// parameters are given by name (missing trailing ones are 0 where the row says so).
//
//   zcheck::LensSpec spec{"opencv_fisheye", {fx, fy, cx, cy, k1, k2, k3, k4}};
//   const zcheck::LensModel lens(spec, 1920, 1080);           // validates; throws Error
//   if (auto dCam = lens.directionFromImage({960.5, 540.5})) ...  // unit ray, camera frame
#include <glm/glm.hpp>

#include <cmath>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace zcheck {

// What a camera file or importer says: a model's name and its parameters in the model's order.
struct LensSpec {
    std::string model;
    std::vector<double> params;

    bool operator==(const LensSpec& other) const { return model == other.model && params == other.params; }
    bool operator!=(const LensSpec& other) const { return !(*this == other); }
};

// One model as data: its name, where it comes from, its parameters and what they mean.
struct LensModelInfo {
    const char* name;       // "opencv_fisheye"
    const char* title;      // "OpenCV fisheye (Kannala–Brandt)"
    const char* formula;    // the forward map, one line, for docs and --help
    std::vector<const char*> params;  // in order: "fx", "fy", "cx", "cy", "k1", ...
    int required;           // the first `required` parameters must be given; the rest default to 0
    bool hasFocal;          // it has a focal length and a principal point (all but panoramas)
    // Its first four parameters are OpenCV's fx, fy, cx, cy (a K beside its coefficients; not
    // Metashape's f, cx, cy, b1, b2 nor a panorama's ranges).
    bool startsWithK() const { return hasFocal && std::string(params[0]) == "fx"; }
};

const std::vector<LensModelInfo>& lensModels();
// The row named `name`; nullptr for none.
const LensModelInfo* lensModelNamed(const std::string& name);
// "opencv, opencv_fisheye, ...": for messages.
std::string lensModelNames();

// A validated lens model for an image of width × height pixels. Immutable; share freely.
class LensModel {
public:
    // Throws Error "lens model <name>: <param> ..." for an unknown model, a wrong number of
    // parameters, a value not finite or outside the model's range (fx, fy > 0; FOV ω in (0, π);
    // unified ξ ≥ 0; EUCM α ∈ [0, 1], β > 0; double sphere α ∈ [0, 1], ξ in (−1, 1); panorama
    // ranges within 360° × 180°), a field of no width, and a lens that folds inside the image.
    LensModel(const LensSpec& spec, int width, int height);
    // The model for (spec, width, height), built once and shared while anyone holds it: the cameras
    // of a dataset's frames that share intrinsics share one, and its field's search. Thread-safe;
    // throws as the constructor does.
    static std::shared_ptr<const LensModel> shared(const LensSpec& spec, int width, int height);

    const LensSpec& spec() const { return spec_; }
    const LensModelInfo& info() const { return *info_; }
    // The parameter named `name` (0 for one the model does not have).
    double param(const std::string& name) const;

    // The image point of a direction in the camera frame (any length > 0); empty outside the
    // valid field.
    std::optional<glm::dvec2> imageFromDirection(const glm::dvec3& dCam) const;
    // How far the image point moves per radian the direction turns, at its most, around direction
    // dCam (camera frame, any length > 0): the largest singular value of imageFromDirection's
    // Jacobian on the sphere of directions, by central differences 10⁻⁷ rad either side (one side
    // where the other leaves the field). About the focal length in pixels on a mild lens; far more
    // where a lens nears a fold. 0 where no side is in the field (or dCam is not).
    double pixelsPerRadian(const glm::dvec3& dCam) const;
    // The unit direction, camera frame, through image point pImage; empty outside the valid
    // field (or where the inverse does not converge: then the pixel is outside it too).
    std::optional<glm::dvec3> directionFromImage(const glm::dvec2& pImage) const;

    // The unit direction through pixel (col, row)'s centre, directionFromImage's to within its
    // convergence test, from a table of every pixel's built on the first call (on every core, each
    // pixel's Newton started from its left neighbour's answer) and kept with the model: 24 bytes a
    // pixel, shared by every camera — every frame of a dataset — with these intrinsics
    // (LensModel::shared). Empty outside the field; a pixel outside the image is computed.
    std::optional<glm::dvec3> directionAtPixel(int col, int row) const;
    // That table itself, built on the first call: width × height unit directions, row by row from
    // the top, NaN outside the field (the ray route reads it per lane).
    const glm::dvec3* pixelDirections() const;
    // directionFromImage, a pixel centre's from that table (the ray route's and verify's points).
    std::optional<glm::dvec3> directionThrough(const glm::dvec2& pImage) const
    {
        const double col = pImage.x - 0.5, row = pImage.y - 0.5;
        if (col == std::floor(col) && row == std::floor(row)) return directionAtPixel(int(col), int(row));
        return directionFromImage(pImage);
    }

    // The largest angle from the axis (radians) the field reaches; for the panorama, π. (A Blender
    // lens polynomial with k0 < 0 also has no pixel for the directions within −k0 of the axis.)
    double fieldAngle() const { return fieldAngle_; }
    // Whether a direction's angle from the axis can exceed 90°, where eye-z is not defined.
    bool seesBehind() const { return fieldAngle_ > kHalfPi; }
    bool isPanorama() const { return panorama_; }

    // The inverse's convergence test, in pixels (module comment).
    static constexpr double kInverseTolerancePx = 1e-10;
    static constexpr double kHalfPi = 1.57079632679489661923;

    // The evaluated terms of the chain (module comment), public for tests and the fits that
    // perturb them; built from the spec by the model's row.
    enum class Profile { Perspective, Equidistant, Equisolid, Fov, Division, Unified, Eucm, DoubleSphere };
    struct Terms {
        Profile profile = Profile::Perspective;
        double profileA = 0, profileB = 0;  // FOV ω; division k; unified ξ; EUCM α, β; double sphere ξ, α
        double numerator[6] = {0, 0, 0, 0, 0, 0};  // N(r²) = 1 + Σ a_i r^(2i)
        double denominator[3] = {0, 0, 0};         // D(r²) = 1 + Σ b_i r^(2i)
        double p1 = 0, p2 = 0;                     // OpenCV's tangential pair
        double s[4] = {0, 0, 0, 0};                // OpenCV's thin prism s1..s4
        double tauX = 0, tauY = 0;                 // OpenCV's tilt, radians
        bool tangentialAfterRadial = false;        // FISHEYE624: T and S on m·N/D
        double fieldLimit = 0;                     // the model's own end of the field (radians); 0: its profile's
        double fx = 1, fy = 1, skew = 0, cx = 0, cy = 0;
        // panorama: longitude and latitude ranges, radians
        double lonMin = 0, lonMax = 0, latMin = 0, latMax = 0;
        // Blender Cycles' panoramic cameras (module comment): the type, and its settings as Blender
        // names them — fisheye_fov (radians), fisheye_lens (mm), the sensor after Blender's sensor
        // fit (mm), the lens polynomial's k0..k4 (radians per mmⁱ), shift in widths and heights.
        enum class Blender { None, FisheyeEquidistant, FisheyeEquisolid, FisheyeLensPolynomial, MirrorBall, CubemapFace };
        Blender blender = Blender::None;
        double fisheyeFov = 0, fisheyeLens = 0, sensorWidth = 0, sensorHeight = 0;
        double polynomial[5] = {0, 0, 0, 0, 0};
        double shiftX = 0, shiftY = 0;
    };
    const Terms& terms() const { return terms_; }

    // Each stage on its own (module comment), for tests: ρ(θ) and its inverse; the plane
    // distortion m ↦ m' (before the affine) and its inverse (empty where Newton fails).
    double profileRadius(double theta) const;
    double profileAngle(double radius) const;
    glm::dvec2 distortPlane(const glm::dvec2& m) const;
    std::optional<glm::dvec2> undistortPlane(const glm::dvec2& mDistorted) const;

private:
    // A neighbouring image point's inverse, where the next point's Newton starts (the table's scan
    // along a row): from there it takes one or two steps instead of four or five. The answer is
    // the same to within the convergence test from any start: inside the field the root is unique.
    struct InverseHint {
        glm::dvec2 distorted{0.0}, undistorted{0.0};
        double radialSlope = 0;  // d|m'|/d|m| there, when the distortion is radial (else 0)
        bool valid = false;
    };
    std::optional<glm::dvec2> undistortPlane(const glm::dvec2& mDistorted, InverseHint* hint) const;
    std::optional<glm::dvec3> directionFromImage(const glm::dvec2& pImage, InverseHint* hint) const;
    bool planeIsIdentity() const;
    bool planeIsRadial() const;
    double radialFactor(double r2) const;       // N(r²)/D(r²)
    double radialDenominator(double r2) const;  // D(r²)
    double distortedRadius(double r) const { return r * radialFactor(r * r); }
    glm::dmat2 planeJacobian(const glm::dvec2& m) const;
    void findField();
    bool profileEndsAt(double theta) const;  // whether θ is at (or past) the profile's own end
    void requireNoFoldInImage() const;
    // Blender's panoramic cameras (module comment): the settings' rules and the field; the two
    // directions; the lens polynomial θ(R) = −(k0 + k1R + … + k4R⁴), its slope, and its inverse on
    // the field [0, fieldRadius_] (empty outside it).
    void setUpBlender();
    std::optional<glm::dvec2> blenderImageFromDirection(const glm::dvec3& unit) const;
    std::optional<glm::dvec3> blenderDirectionFromImage(const glm::dvec2& pImage) const;
    double polynomialAngle(double radiusMm) const;
    double polynomialSlope(double radiusMm) const;
    std::optional<double> polynomialRadius(double theta) const;

    LensSpec spec_;
    int width_ = 0, height_ = 0;
    const LensModelInfo* info_ = nullptr;
    Terms terms_;
    bool panorama_ = false;
    double fieldAngle_ = 0;    // θ_max
    double fieldRadius_ = 0;   // ρ(θ_max): the undistorted plane's radius at the field's edge (Blender's: |q|, or mm)
    double fieldDistortedRadius_ = INFINITY;  // |m'| there, where the radial map reaches (∞: no bound)
    bool fieldEndsInFold_ = false;  // the field ends where the distortion folds, not where the profile ends
    glm::dmat3 tilt_{1.0}, untilt_{1.0};
    mutable std::once_flag tableOnce_;
    mutable std::vector<glm::dvec3> table_;  // directionAtPixel's, NaN outside the field
};

}  // namespace zcheck
