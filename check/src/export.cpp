#include "zcheck/export.h"

#include "zcheck/error.h"
#include "zcheck/inverse_projection.h"

#include <cmath>
#include <optional>

namespace zcheck {

QuantityImage quantityImageShape(const Camera& camera, ExportQuantity quantity)
{
    QuantityImage image;
    image.quantity = quantity;
    image.width = camera.width(), image.height = camera.height();
    switch (quantity) {
    case ExportQuantity::Window: image.channels = {channelNameOf(quantity)}, image.unit = "depth-buffer value", image.missValue = camera.clearDepth(); break;
    case ExportQuantity::Ndc: image.channels = {channelNameOf(quantity)}, image.unit = "NDC z", image.missValue = camera.ndcZFar(); break;
    case ExportQuantity::EyeZ: image.channels = {channelNameOf(quantity)}, image.unit = "scene units (planar depth)", image.missValue = INFINITY; break;
    case ExportQuantity::Distance: image.channels = {channelNameOf(quantity)}, image.unit = "scene units (range)", image.missValue = INFINITY; break;
    case ExportQuantity::PositionEye: image.channels = {"P.X", "P.Y", "P.Z"}, image.unit = "scene units, eye space", image.missValue = NAN; break;
    case ExportQuantity::PositionWorld: image.channels = {"Pw.X", "Pw.Y", "Pw.Z"}, image.unit = "scene units, world space", image.missValue = NAN; break;
    case ExportQuantity::Normal: image.channels = {"N.X", "N.Y", "N.Z"}, image.unit = "unit vector, world space, facing the camera", image.missValue = NAN; break;
    case ExportQuantity::PrimitiveId: image.channels = {"id"}, image.unit = "triangle index (uint32)", image.missValue = double(kNoPrimitive); break;
    }
    if (quantity == ExportQuantity::Window || quantity == ExportQuantity::Ndc)
        requireQuantityOf(camera, quantity == ExportQuantity::Window ? DepthQuantity::Window : DepthQuantity::Ndc,
                          "quantity " + toString(quantity));
    return image;
}

QuantityImage quantityImage(const Scene& scene, const Camera& camera, const RenderResult& route, ExportQuantity quantity)
{
    QuantityImage image = quantityImageShape(camera, quantity);
    const std::size_t pixels = std::size_t(image.width) * image.height, C = image.channels.size();
    if (quantity == ExportQuantity::PrimitiveId) {
        image.id.assign(route.primitiveId.begin(), route.primitiveId.end());
        return image;
    }
    image.value.assign(pixels * C, image.missValue);
    for (int row = 0; row < image.height; ++row)
        for (int col = 0; col < image.width; ++col) {
            const std::size_t i = std::size_t(row) * image.width + col;
            if (!route.hit(i)) continue;
            const glm::dvec2 pWindow = windowFromPixelCentre(camera, col, row);
            const double windowDepth = route.windowDepth.value[i];
            // The ray route carries the exact hit (when asked to keep it); otherwise the point is
            // unprojected from the route's depth: the stored depth of the raster route, and a lens
            // camera's distance along the pixel's ray (it has no depth buffer).
            glm::dvec3 pEye;
            if (!route.pEye.empty()) {
                pEye = route.pEye[i];
            } else if (camera.lens()) {
                const std::optional<glm::dvec3> p = eyePointFromDepth(camera, pWindow, windowDepth, DepthQuantity::Distance);
                if (!p) continue;  // no ray there: outside the lens's field
                pEye = *p;
            } else {
                pEye = eyeFromWindow(camera, {pWindow, windowDepth});
            }
            double* out = &image.value[i * C];
            switch (quantity) {
            case ExportQuantity::Window: out[0] = windowDepth; break;
            case ExportQuantity::Ndc: out[0] = camera.ndcZFromWindowDepth(windowDepth); break;
            case ExportQuantity::EyeZ:
                out[0] = camera.eyeZOf(pEye);
                if (camera.lens() && !(out[0] > 0))  // a lens's ray 90° or more off the axis
                    throw Error("quantity eye-z: the lens model " + camera.lens()->spec().model + " sees pixel (" +
                                std::to_string(col) + ", " + std::to_string(row) +
                                ") hit 90° or more off the axis, where eye-z does not exist; export distance");
                break;
            case ExportQuantity::Distance: out[0] = distanceOfEyePoint(camera, pEye); break;
            case ExportQuantity::PositionEye: out[0] = pEye.x, out[1] = pEye.y, out[2] = pEye.z; break;
            case ExportQuantity::PositionWorld: {
                const glm::dvec3 pWorld(camera.worldFromEye * glm::dvec4(pEye, 1.0));
                out[0] = pWorld.x, out[1] = pWorld.y, out[2] = pWorld.z;
                break;
            }
            case ExportQuantity::Normal: {
                const glm::uvec3 t = scene.triangles[route.primitiveId[i]];
                const glm::dvec3 a(scene.positions[t[0]]), b(scene.positions[t[1]]), c(scene.positions[t[2]]);
                glm::dvec3 n = glm::normalize(glm::cross(b - a, c - a));
                // Face the viewer: against the viewing ray (for parallel projections too).
                const glm::dvec3 rayDirection = worldEyePlaneRayThroughWindow(camera, pWindow).direction;
                if (glm::dot(n, rayDirection) > 0) n = -n;
                out[0] = n.x, out[1] = n.y, out[2] = n.z;
                break;
            }
            case ExportQuantity::PrimitiveId: break;
            }
        }
    return image;
}

}  // namespace zcheck
