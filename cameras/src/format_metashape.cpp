// Agisoft Metashape's (and PhotoScan's) camera export, cameras.xml (File > Export > Cameras,
// "Agisoft XML"), as Metashape defines it (user manual, appendix "Camera models"; the export
// scripts Agisoft publishes):
//
//   sensors  <sensor id type="frame|fisheye|spherical"> with <calibration class="adjusted">
//            (else the only one): <resolution width height>, f, cx, cy as offsets from the image
//            centre, b1 (affinity), b2 (skew), k1..k4, p1..p4; absent parameters are 0.
//            frame: u = W/2 + cx + x'(f + b1) + y'·b2, v = H/2 + cy + y'·f, x', y' the Brown
//            polynomial of (X/Z, Y/Z) with P1 on r² + 2x² (OpenCV's p2) → lens metashape_frame
//            [f, cx, cy, b1, b2, k1..k4, p1, p2], cx, cy moved to zcheck's W/2 + cx − ½; with every
//            k, p and b2 zero, a pinhole fx = f + b1, fy = f
//            fisheye: the same on the equidistant point (X, Y)·θ/r → lens metashape_fisheye
//            spherical: no calibration (nerfstudio's metashape_utils.py reads it so, with its
//            EQUIRECTANGULAR fl_x = W/2, cx = W/2, fl_y = H, cy = H/2 in the camera's own axes;
//            Agisoft's render_spherical_panorama.py renders one with f = H/π and W = 2H): the
//            whole sphere, longitude atan2(X, Z) 0 at the image's centre column, the top row up
//            (−Y) → lens equirectangular −180..180, −90..90
//   pixels   the image's top-left corner is (0, 0): the top-left pixel's centre is (0.5, 0.5)
//   cameras  <camera id sensor_id [component_id] label [enabled="false"]>, also one level down
//            in a <group>; <transform>: 16 numbers, row-major, camera-to-chunk
//   axes     OpenCV: x right, y down, z forward
//   world    the chunk's <transform> (<rotation> 9, <translation> 3, <scale> 1: world =
//            s·R·p + t), or, in 2.x files, the camera's component's; none: the chunk's
//            internal coordinates (noted)
//
// Disabled cameras are skipped, as Metashape's own exporters skip them. A camera the file cannot
// give a camera for keeps its refusal (dataset frames record it and go on): one not aligned
// (no <transform>), a rig's secondary camera (master_id), one whose sensor is of another type
// (cylindrical, rpc), has no calibration, or has p3, p4 (a factor on the tangential terms the
// lens models do not have); a spherical sensor whose image is not 2:1 or whose calibration is not
// the plain sphere. PhotoScan's older calibrations (fx, fy instead of f) are refused: their model
// differs.
#include "formats.h"

#include "zcheck/detail/xml_lite.h"
#include "zcheck/error.h"
#include "zcheck/input_file.h"
#include "zcheck/lens.h"
#include "zcheck/pose.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

namespace zcheck::formats {

const CameraFormat& metashapeFormat();

namespace {

using xml::Element;

// A sensor's calibration as the cameras on it need it: the projection, or why there is none.
struct Sensor {
    Projection projection;
    int width = 0, height = 0;
    std::string refusal;
};

// world = scale · rotation · p + translation.
struct Similarity {
    glm::dmat3 rotation{1.0};
    glm::dvec3 translation{0.0};
    double scale = 1;
};

class MetashapeReader {
public:
    MetashapeReader(std::string_view bytes, const std::string& path) : path_(path), root_(xml::parse(bytes, source()))
    {
        if (root_.name != "document") fail(root_, "the root element must be <document>, as Metashape writes it");
        chunk_ = root_.child("chunk");
        if (!chunk_) fail(root_, "holds no <chunk>");
        if (const Element* second = nextChunk()) fail(*second, "holds several chunks: export the cameras of one chunk");
    }

    CameraSet read()
    {
        readSensors();
        const std::optional<Similarity> chunk = similarityOf(chunk_->child("transform"));
        readComponents();
        CameraSet set;
        const Element* cameras = chunk_->child("cameras");
        if (!cameras) fail(*chunk_, "holds no <cameras>");
        for (const Element& child : cameras->children) {
            if (child.name == "camera") addCamera(child, chunk, set);
            if (child.name == "group")
                for (const Element& grouped : child.children)
                    if (grouped.name == "camera") addCamera(grouped, chunk, set);
        }
        return set;
    }

private:
    std::string source() const { return "Metashape cameras file '" + path_ + "'"; }
    [[noreturn]] void fail(const Element& at, const std::string& why) const
    {
        throw Error(source() + ": line " + std::to_string(at.line) + ": <" + at.name + "> " + why);
    }

    const Element* nextChunk() const
    {
        bool first = true;
        for (const Element& child : root_.children)
            if (child.name == "chunk") {
                if (!first) return &child;
                first = false;
            }
        return nullptr;
    }

    const std::string& attribute(const Element& element, const std::string& name) const
    {
        const std::string* value = element.attribute(name);
        if (!value) fail(element, "has no '" + name + "' attribute");
        return *value;
    }

    std::vector<double> numbers(const Element& element, std::size_t count) const
    {
        std::vector<double> out;
        std::size_t at = 0;
        const std::string& text = element.text;
        while (at < text.size()) {
            const std::size_t start = text.find_first_not_of(" \t\n", at);
            if (start == std::string::npos) break;
            const std::size_t end = std::min(text.find_first_of(" \t\n", start), text.size());
            double value = 0;
            if (!parseFiniteNumber(std::string_view(text).substr(start, end - start), value))
                fail(element, "holds '" + text.substr(start, end - start) + "', not a finite number");
            out.push_back(value);
            at = end;
        }
        if (out.size() != count)
            fail(element, "holds " + std::to_string(out.size()) + " numbers; it takes " + std::to_string(count));
        return out;
    }

    double number(const Element& element) const { return numbers(element, 1)[0]; }

    int pixels(const Element& resolution, const std::string& name) const
    {
        double value = 0;
        if (!parseFiniteNumber(attribute(resolution, name), value) || value != std::floor(value) ||
            !Camera::isImageSide(value))
            fail(resolution, name + " '" + attribute(resolution, name) + "' is not an image side (1.." +
                                 std::to_string(Camera::kMaxImageSide) + " pixels)");
        return int(value);
    }

    // The calibration the poses were solved with: the adjusted one, else the only one.
    const Element* calibrationOf(const Element& sensor) const
    {
        const Element* only = nullptr;
        int count = 0;
        for (const Element& child : sensor.children) {
            if (child.name != "calibration") continue;
            const std::string* kind = child.attribute("class");
            if (kind && *kind == "adjusted") return &child;
            only = &child, ++count;
        }
        return count == 1 ? only : nullptr;
    }

    void readSensors()
    {
        const Element* sensors = chunk_->child("sensors");
        if (!sensors) fail(*chunk_, "holds no <sensors>");
        for (const Element& element : sensors->children) {
            if (element.name != "sensor") continue;
            const std::string& id = attribute(element, "id");
            if (sensors_.count(id)) fail(element, "repeats sensor id " + id);
            sensors_[id] = sensorOf(element, id);
        }
    }

    const Element& resolutionOf(const Element& sensor, const Element* calibration) const
    {
        const Element* resolution = calibration ? calibration->child("resolution") : nullptr;
        if (!resolution) resolution = sensor.child("resolution");
        if (!resolution) fail(calibration ? *calibration : sensor, "has no <resolution> (nor has its sensor)");
        return *resolution;
    }

    Sensor sensorOf(const Element& element, const std::string& id) const
    {
        Sensor sensor;
        const std::string where = source() + ": sensor " + id;
        const std::string* typeAttribute = element.attribute("type");
        const std::string type = typeAttribute ? *typeAttribute : "frame";
        if (type != "frame" && type != "fisheye" && type != "spherical") {
            sensor.refusal = where + " (line " + std::to_string(element.line) + ") is a " + type +
                             " camera: zcheck reads Metashape's frame, fisheye and spherical sensors";
            return sensor;
        }
        const Element* calibration = calibrationOf(element);
        if (type == "spherical") return sphericalSensor(element, calibration, where);
        if (!calibration) {
            sensor.refusal = where + " has no calibration (or several, none adjusted): align the cameras first";
            return sensor;
        }
        if (calibration->child("fx") || calibration->child("fy"))
            fail(*calibration, "gives fx, fy (PhotoScan's older model): re-export the cameras with Metashape");
        const Element& resolution = resolutionOf(element, calibration);
        sensor.width = pixels(resolution, "width"), sensor.height = pixels(resolution, "height");
        const auto value = [&](const char* name) {
            const Element* child = calibration->child(name);
            return child ? number(*child) : 0.0;
        };
        const Element* f = calibration->child("f");
        if (!f) fail(*calibration, "has no <f>");
        const std::string at = where + " (calibration, line " + std::to_string(calibration->line) + ")";
        for (const char* name : {"p3", "p4"})
            if (value(name) != 0) {
                sensor.refusal = at + " has " + name + " = " + formatNumber(value(name)) +
                                 ": Metashape's factor 1 + P3·r² + P4·r⁴ on the tangential terms is in no lens model "
                                 "zcheck has";
                return sensor;
            }
        const double focal = number(*f), b1 = value("b1"), b2 = value("b2");
        std::vector<double> distortion;
        bool distorted = false;
        for (const char* name : {"k1", "k2", "k3", "k4", "p1", "p2"}) {
            distortion.push_back(value(name));
            distorted = distorted || distortion.back() != 0;
        }
        try {
            if (type == "frame" && !distorted && b2 == 0) {
                const double k[3][3] = {{focal + b1, 0, sensor.width / 2.0 + value("cx")},
                                        {0, focal, sensor.height / 2.0 + value("cy")},
                                        {0, 0, 1}};
                sensor.projection = PinholeIntrinsics::fromK(k, 0.5, "calibration (f + b1, f, W/2 + cx, H/2 + cy)")
                                        .projection(kPlaceholderNear, kPlaceholderFar, "calibration");
            } else {
                // The lens's f, cx, cy, b1, b2, k1..k4, p1, p2, cx and cy in zcheck's pixel
                // coordinates (the top-left pixel's centre at 0, 0): W/2 + cx − ½.
                std::vector<double> params = {focal, sensor.width / 2.0 + value("cx") - 0.5,
                                              sensor.height / 2.0 + value("cy") - 0.5, b1, b2};
                params.insert(params.end(), distortion.begin(), distortion.end());
                sensor.projection = lensProjection(type == "frame" ? "metashape_frame" : "metashape_fisheye", params);
                const LensModel validated(sensor.projection.lens, sensor.width, sensor.height);
            }
        } catch (const Error& e) {
            sensor.refusal = at + ": " + e.what();
        }
        return sensor;
    }

    static Projection lensProjection(const std::string& model, const std::vector<double>& params)
    {
        Projection p;
        p.type = ProjectionType::NonLinear;
        p.lens = {model, params};
        p.near = kPlaceholderNear, p.far = kPlaceholderFar;
        return p;
    }

    // A spherical sensor: the whole sphere over a 2:1 image (the module comment's sources).
    Sensor sphericalSensor(const Element& element, const Element* calibration, const std::string& where) const
    {
        Sensor sensor;
        const Element& resolution = resolutionOf(element, calibration);
        sensor.width = pixels(resolution, "width"), sensor.height = pixels(resolution, "height");
        const std::string at = where + " (spherical, line " + std::to_string(element.line) + ")";
        if (sensor.width != 2 * sensor.height) {
            sensor.refusal = at + " is " + std::to_string(sensor.width) + "x" + std::to_string(sensor.height) +
                             ": Metashape's spherical image is read as the whole sphere, 2:1 (width = 2 x height)";
            return sensor;
        }
        if (calibration) {  // only the sphere's own: f = H/π pixels per radian, nothing else
            for (const Element& child : calibration->children) {
                static const char* const kParameters[] = {"f",  "cx", "cy", "b1", "b2", "k1", "k2",
                                                          "k3", "k4", "p1", "p2", "p3", "p4"};
                if (std::find(std::begin(kParameters), std::end(kParameters), child.name) == std::end(kParameters))
                    continue;
                const double value = number(child);
                const double expected = child.name == "f" ? sensor.height / M_PI : 0.0;
                if (std::abs(value - expected) > 1e-9 * std::max(1.0, expected)) {
                    sensor.refusal = at + ": its calibration (line " + std::to_string(child.line) + ") gives " +
                                     child.name + " = " + formatNumber(value) +
                                     "; zcheck reads a spherical sensor as the plain sphere (f = H/π = " +
                                     formatNumber(sensor.height / M_PI) + ", every other parameter 0)";
                    return sensor;
                }
            }
        }
        sensor.projection = lensProjection("equirectangular", {-180, 180, -90, 90});
        return sensor;
    }

    std::optional<Similarity> similarityOf(const Element* transform) const
    {
        if (!transform) return std::nullopt;
        Similarity s;
        if (const Element* r = transform->child("rotation")) {
            const std::vector<double> v = numbers(*r, 9);
            for (int row = 0; row < 3; ++row)
                for (int col = 0; col < 3; ++col) s.rotation[col][row] = v[std::size_t(row * 3 + col)];
        }
        if (const Element* t = transform->child("translation")) {
            const std::vector<double> v = numbers(*t, 3);
            s.translation = {v[0], v[1], v[2]};
        }
        if (const Element* scale = transform->child("scale")) {
            s.scale = number(*scale);
            if (!(s.scale > 0)) fail(*scale, "must be a positive number");
        }
        return s;
    }

    void readComponents()
    {
        const Element* components = chunk_->child("components");
        if (!components) return;
        for (const Element& element : components->children)
            if (element.name == "component")
                if (std::optional<Similarity> s = similarityOf(element.child("transform")))
                    components_[attribute(element, "id")] = *s;
    }

    void addCamera(const Element& element, const std::optional<Similarity>& chunk, CameraSet& set) const
    {
        const std::string* enabled = element.attribute("enabled");
        if (enabled && (*enabled == "false" || *enabled == "0")) return;
        ImportedCamera camera;
        camera.name = attribute(element, "label");
        camera.aliases = pathAliases(camera.name);
        camera.aliases.push_back("id" + attribute(element, "id"));
        const std::string where = source() + ": camera '" + camera.name + "'";
        const Element* transform = element.child("transform");
        const auto sensor = sensors_.find(attribute(element, "sensor_id"));
        if (sensor == sensors_.end()) fail(element, "names sensor " + attribute(element, "sensor_id") + ", which the file has not");
        if (element.attribute("master_id") && !transform)
            camera.refusal = where + " is a secondary camera of a rig (master_id): zcheck reads the rig's cameras "
                                     "that have their own <transform>";
        else if (!transform)
            camera.refusal = where + " is not aligned (it has no <transform>)";
        else
            camera.refusal = sensor->second.refusal;
        if (!camera.refusal.empty()) {
            set.cameras.push_back(std::move(camera));
            return;
        }
        const Sensor& k = sensor->second;
        CameraSpec& spec = camera.spec;
        const Convention opencv = Convention::preset("opencv");
        spec.convention = opencv;
        spec.width = k.width, spec.height = k.height;
        try {
            spec.projection = k.projection;
            spec.view = viewFromPose(worldFromCamera(element, *transform, chunk), PoseDirection::WorldFromCamera, opencv,
                                     opencv, "<transform>");
            Camera validated(spec);
        } catch (const Error& e) {
            throw Error(where + " (line " + std::to_string(element.line) + "): " + e.what());
        }
        if (!chunk && !similarityFor(element)) spec.notes.push_back(noSimilarityNote());
        set.cameras.push_back(std::move(camera));
    }

    const Similarity* similarityFor(const Element& camera) const
    {
        const std::string* component = camera.attribute("component_id");
        if (!component) return nullptr;
        const auto found = components_.find(*component);
        return found == components_.end() ? nullptr : &found->second;
    }

    // [R·Rc | s·R·tc + t]: the camera-to-chunk transform taken into the world by the similarity.
    glm::dmat4 worldFromCamera(const Element& camera, const Element& transform, const std::optional<Similarity>& chunk) const
    {
        const std::vector<double> v = numbers(transform, 16);
        glm::dmat4 chunkFromCamera(1.0);
        for (int row = 0; row < 4; ++row)
            for (int col = 0; col < 4; ++col) chunkFromCamera[col][row] = v[std::size_t(row * 4 + col)];
        const Similarity* component = similarityFor(camera);
        if (component && chunk)
            fail(camera, "is in a component with its own <transform> and the chunk has one too: which one places "
                         "the camera is not defined");
        const Similarity s = component ? *component : chunk.value_or(Similarity{});
        if (!hasRigidLastRow(chunkFromCamera)) fail(transform, "must end in the row 0 0 0 1");
        glm::dmat4 world(s.rotation * glm::dmat3(chunkFromCamera));
        world[3] = glm::dvec4(s.scale * (s.rotation * glm::dvec3(chunkFromCamera[3])) + s.translation, 1.0);
        return world;
    }

    static std::string noSimilarityNote()
    {
        return "the Metashape file gives no chunk or component <transform>: the pose is in the chunk's internal "
               "coordinates, which the mesh must share";
    }

    std::string path_;
    Element root_;
    const Element* chunk_ = nullptr;
    std::map<std::string, Sensor> sensors_;
    std::map<std::string, Similarity> components_;
};

CameraSet readMetashape(std::string_view bytes, const std::string& path) { return MetashapeReader(bytes, path).read(); }

bool detectsMetashape(const CameraFileHead& file)
{
    return file.looksLikeXml() && file.has("<document") && (file.has("<chunk") || file.has("<sensors"));
}

}  // namespace

const CameraFormat& metashapeFormat()
{
    static const CameraFormat row = [] {
        CameraFormat f;
        f.name = "metashape";
        f.aliases = {"photoscan"};
        f.title = "Metashape cameras.xml";
        f.extensions = {".xml"};
        f.files = "Agisoft Metashape's XML camera export: frame, fisheye and spherical sensors, each camera's "
                  "camera-to-chunk transform and the chunk's (disabled cameras skipped)";
        f.example = "cameras.xml#IMG_0001.JPG";
        f.priority = 35;
        f.detects = detectsMetashape;
        f.parse = readMetashape;
        f.datasetSource = true;
        return f;
    }();
    return row;
}

}  // namespace zcheck::formats
