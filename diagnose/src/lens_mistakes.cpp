// The lens family's mistakes, each as the renderer made it (lens_mistakes.h has the list).
#include "zcheck/lens_mistakes.h"

#include "zcheck/error.h"
#include "zcheck/remap.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace zcheck {

namespace {

std::string coefficientText(const LensSpec& lens, const std::vector<std::size_t>& which)
{
    const LensModelInfo& info = *lensModelNamed(lens.model);
    std::string out;
    for (std::size_t i : which) {
        char value[48];
        std::snprintf(value, sizeof value, "%.6g", lens.params[i]);
        out += (out.empty() ? "" : ", ") + std::string(info.params[i]) + " " + value;
    }
    return out;
}

CameraSpec withLens(const Camera& camera, LensSpec lens)
{
    CameraSpec spec = camera.spec();
    spec.projection.lens = std::move(lens);
    return spec;
}

}  // namespace

std::size_t lensParamIndex(const LensSpec& lens, const char* name)
{
    const LensModelInfo& info = *lensModelNamed(lens.model);
    for (std::size_t i = 0; i < info.params.size(); ++i)
        if (std::string(info.params[i]) == name) return i;
    return std::string::npos;
}

std::vector<LensMistake> lensMistakes(const Camera& camera, DepthQuantity declaredQuantity)
{
    std::vector<LensMistake> out;
    const LensModel& lens = *camera.lens();
    const LensModelInfo& info = lens.info();
    // Every parameter of the model, the trailing ones a file may leave out 0 (lens.h): the
    // mistakes below read and write them by the model's index.
    LensSpec spec = lens.spec();
    spec.params.resize(std::max(spec.params.size(), info.params.size()), 0.0);
    const bool hasK = info.startsWithK();
    if (hasK) {
        CameraSpec pinhole = camera.spec();
        pinhole.projection = Projection{};
        pinhole.projection.type = ProjectionType::Pinhole;
        pinhole.projection.fx = spec.params[0], pinhole.projection.fy = spec.params[1];
        pinhole.projection.cx = spec.params[2], pinhole.projection.cy = spec.params[3];
        pinhole.projection.near = camera.nearDistance(), pinhole.projection.far = camera.farDistance();
        out.push_back({"distortion-ignored", "", "consistent if the map was made through the lens's K alone, its " +
                                                    spec.model + " distortion left out (the original K kept after undistorting)",
                       pinhole, std::nullopt});
    }
    for (const double alpha : {0.0, 1.0}) {
        try {
            const CameraSpec undistorted = undistortedCameraSpec(camera, alpha);
            char text[160];
            std::snprintf(text, sizeof text, "the new K of getOptimalNewCameraMatrix with alpha %g: fx %.6g, fy %.6g, cx %.6g, cy %.6g",
                          alpha, undistorted.projection.fx, undistorted.projection.fy, undistorted.projection.cx,
                          undistorted.projection.cy);
            out.push_back({"undistorted-new-k", alpha == 0 ? "alpha 0" : "alpha 1",
                           std::string("consistent if the map was undistorted to ") + text, undistorted, std::nullopt});
        } catch (const Error&) {  // a fisheye past 180°, a panorama: no pinhole holds it
        }
    }
    // Coefficient orders: the file's numbers read in another order.
    const auto reordered = [&](const std::vector<const char*>& asRead, const std::vector<const char*>& meant) {
        LensSpec other = spec;
        for (std::size_t k = 0; k < asRead.size(); ++k) other.params[lensParamIndex(spec, meant[k])] = spec.params[lensParamIndex(spec, asRead[k])];
        return other;
    };
    if (spec.model == "opencv") {
        const std::vector<const char*> opencvOrder = {"k1", "k2", "p1", "p2", "k3"};
        const std::vector<const char*> radialFirst = {"k1", "k2", "k3", "p1", "p2"};
        out.push_back({"coefficient-order", "k1 k2 k3 p1 p2 read as k1 k2 p1 p2 k3",
                       "consistent if the five coefficients were written k1 k2 k3 p1 p2 and read in OpenCV's order",
                       withLens(camera, reordered(opencvOrder, radialFirst)), std::nullopt});
        out.push_back({"coefficient-order", "k1 k2 p1 p2 k3 read as k1 k2 k3 p1 p2",
                       "consistent if OpenCV's k1 k2 p1 p2 k3 were read as k1 k2 k3 p1 p2",
                       withLens(camera, reordered(radialFirst, opencvOrder)), std::nullopt});
    }
    if (spec.model == "brown_conrady") {
        const std::vector<const char*> nerfstudioOrder = {"k1", "k2", "k3", "k4", "p1", "p2"};
        const std::vector<const char*> opencvLike = {"k1", "k2", "p1", "p2", "k3", "k4"};
        out.push_back({"coefficient-order", "k1 k2 p1 p2 k3 k4 read as k1 k2 k3 k4 p1 p2",
                       "consistent if OpenCV-ordered coefficients were read in nerfstudio's order",
                       withLens(camera, reordered(opencvLike, nerfstudioOrder)), std::nullopt});
    }
    // Tangential pair exchanged.
    for (const auto& [a, b] : {std::pair{"p1", "p2"}, std::pair{"p0", "p1"}}) {
        const std::size_t ia = lensParamIndex(spec, a), ib = lensParamIndex(spec, b);
        if (ia == std::string::npos || ib == std::string::npos || spec.params[ia] == spec.params[ib]) continue;
        LensSpec swapped = spec;
        std::swap(swapped.params[ia], swapped.params[ib]);
        out.push_back({"tangential-swapped", "", std::string("consistent if ") + a + " and " + b +
                                                     " were exchanged (Metashape's P1 is OpenCV's p2)",
                       withLens(camera, swapped), std::nullopt});
        break;
    }
    // Every distortion coefficient negated: those after the model's intrinsics that are not a
    // profile's own parameter (ξ, α, β, ω).
    {
        LensSpec negated = spec;
        std::vector<std::size_t> changed;
        for (std::size_t i = 0; i < info.params.size(); ++i) {
            const std::string name = info.params[i];
            const bool coefficient = (name[0] == 'k' || name[0] == 'p' || name[0] == 's') && name.size() <= 3;
            if (coefficient && spec.params[i] != 0) negated.params[i] = -spec.params[i], changed.push_back(i);
        }
        if (!changed.empty())
            out.push_back({"distortion-signs-flipped", "", "consistent if the distortion's signs were flipped (" +
                                                               coefficientText(negated, changed) + ")",
                           withLens(camera, negated), std::nullopt});
    }
    // A fisheye read as another fisheye with the same K.
    const bool fisheye = lens.seesBehind() || spec.model == "opencv_fisheye" || spec.model == "equisolid" ||
                         spec.model == "thin_prism_fisheye" || spec.model == "fisheye624";
    if (hasK && fisheye) {
        const std::vector<double> k(spec.params.begin(), spec.params.begin() + 4);
        const std::vector<std::pair<const char*, LensSpec>> others = {
            {"equidistant", {"opencv_fisheye", k}},
            {"equisolid", {"equisolid", k}},
            {"stereographic", {"unified", {k[0], k[1], k[2], k[3], 1.0}}},
        };
        for (const auto& [label, other] : others) {
            if (other.model == spec.model && other.params.size() == spec.params.size() && other.params == spec.params) continue;
            if (spec.model == "opencv_fisheye" && std::string(label) == "equidistant" &&
                std::all_of(spec.params.begin() + 4, spec.params.end(), [](double v) { return v == 0; }))
                continue;
            out.push_back({"fisheye-model", label, std::string("consistent if the fisheye was rendered ") + label +
                                                       " (same K) where " + spec.model + " was declared",
                           withLens(camera, other), std::nullopt});
        }
    }
    // The generic mistakes of the catalogue's names that a lens map shows alike: the image flipped,
    // the principal point half a pixel off (COLMAP's corner-based cx, cy taken as OpenCV's) or
    // its coordinates exchanged.
    out.push_back({"y-flip", "", "consistent if the map's rows are read bottom to top (a bottom-left image origin)",
                   std::nullopt, std::nullopt, 1});
    out.push_back({"x-flip", "", "consistent if the map is mirrored left to right", std::nullopt, std::nullopt, 2});
    if (hasK) {
        for (const double shift : {0.5, -0.5}) {
            LensSpec moved = spec;
            moved.params[2] += shift, moved.params[3] += shift;
            out.push_back({"half-pixel", shift > 0 ? "+0.5" : "-0.5",
                           std::string("consistent if the principal point is ") + (shift > 0 ? "half a pixel further" : "half a pixel nearer") +
                               " from the top-left corner (pixel centres counted from 0.5 or from 0)",
                           withLens(camera, moved), std::nullopt});
        }
        if (spec.params[2] != spec.params[3]) {
            LensSpec swapped = spec;
            std::swap(swapped.params[2], swapped.params[3]);
            out.push_back({"cx-cy-swapped", "", "consistent if cx and cy were exchanged", withLens(camera, swapped), std::nullopt});
        }
    }
    // The values taken for the other quantity.
    if (declaredQuantity == DepthQuantity::EyeZ)
        out.push_back({"distance-as-eye-z", "", "consistent if read as ray distance instead of eye-z", std::nullopt,
                       DepthQuantity::Distance});
    if (declaredQuantity == DepthQuantity::Distance)
        out.push_back({"eye-z-as-distance", "", "consistent if read as eye-z instead of ray distance", std::nullopt,
                       DepthQuantity::EyeZ});
    return out;
}

DepthMap flippedMap(const DepthMap& map, int flip)
{
    if (flip == 0) return map;
    DepthMap out = map;
    for (int row = 0; row < map.height; ++row)
        for (int col = 0; col < map.width; ++col) {
            const int fromRow = flip == 1 ? map.height - 1 - row : row, fromCol = flip == 2 ? map.width - 1 - col : col;
            out.value[std::size_t(row) * map.width + col] = map.value[std::size_t(fromRow) * map.width + fromCol];
            if (!map.valueStep.empty())
                out.valueStep[std::size_t(row) * map.width + col] = map.valueStep[std::size_t(fromRow) * map.width + fromCol];
        }
    return out;
}

DepthMap renderedMap(const Checker& checker, const Camera& camera, DepthQuantity quantity)
{
    const QuantityImage image = checker.render(camera, exportQuantityOf(quantity), Route::Ray);
    std::vector<double> values(image.value.size());
    for (std::size_t i = 0; i < values.size(); ++i)
        values[i] = image.isMiss(i) || !std::isfinite(image.value[i]) ? 0.0 : roundedToBinary32(image.value[i]);
    return DepthMap::exact(camera.width(), camera.height(), quantity, std::move(values));
}

DepthMap mistakenMap(const Checker& checker, const Camera& declared, DepthQuantity declaredQuantity, const LensMistake& mistake)
{
    const Camera used(mistake.camera ? *mistake.camera : declared.spec());
    DepthMap map = flippedMap(renderedMap(checker, used, mistake.quantity.value_or(declaredQuantity)), mistake.flip);
    map.quantity = declaredQuantity;
    return map;
}

}  // namespace zcheck
