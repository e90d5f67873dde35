// Agisoft Metashape's (and PhotoScan's) camera export, cameras.xml (File > Export > Cameras,
// "Agisoft XML"), as Metashape defines it (user manual, appendix "Camera models"; the export
// scripts Agisoft publishes):
//
//   sensors  <sensor id type="frame"> with <calibration class="adjusted"> (else the only one):
//            <resolution width height>, f, cx, cy as offsets from the image centre, b1
//            (affinity), b2 (skew), k1..k4, p1..p4; absent parameters are 0.
//            fx = f + b1, fy = f, principal point (W/2 + cx, H/2 + cy)
//   pixels   the image's top-left corner is (0, 0): the top-left pixel's centre is (0.5, 0.5)
//   cameras  <camera id sensor_id [component_id] label [enabled="false"]>, also one level down
//            in a <group>; <transform>: 16 numbers, row-major, camera-to-chunk
//   axes     OpenCV: x right, y down, z forward
//   world    the chunk's <transform> (<rotation> 9, <translation> 3, <scale> 1: world =
//            s·R·p + t), or, in 2.x files, the camera's component's; none: the chunk's
//            internal coordinates (noted)
//
// Disabled cameras are skipped, as Metashape's own exporters skip them. A camera the file cannot
// give a pinhole for keeps its refusal (dataset frames record it and go on): one not aligned
// (no <transform>), a rig's secondary camera (master_id), one whose sensor is not a frame
// camera, has no calibration, or has lens distortion (any nonzero k or p) or skew (b2).
// PhotoScan's older calibrations (fx, fy instead of f) are refused: their model differs.
#include "formats.h"

#include "zcheck/detail/xml_lite.h"
#include "zcheck/error.h"
#include "zcheck/input_file.h"
#include "zcheck/pose.h"

#include <map>
#include <optional>

namespace zcheck::formats {

const CameraFormat& metashapeFormat();

namespace {

using xml::Element;

// A sensor's calibration as the cameras on it need it: the projection, or why there is none.
struct Sensor {
    PinholeIntrinsics intrinsics;
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

    Sensor sensorOf(const Element& element, const std::string& id) const
    {
        Sensor sensor;
        const std::string where = source() + ": sensor " + id;
        const std::string* type = element.attribute("type");
        if (type && *type != "frame") {
            sensor.refusal = where + " is a " + *type + " camera, not a frame (pinhole) camera: zcheck checks linear "
                                     "projections; undistort the depth map and give its pinhole camera";
            return sensor;
        }
        const Element* calibration = calibrationOf(element);
        if (!calibration) {
            sensor.refusal = where + " has no calibration (or several, none adjusted): align the cameras first";
            return sensor;
        }
        if (calibration->child("fx") || calibration->child("fy"))
            fail(*calibration, "gives fx, fy (PhotoScan's older model): re-export the cameras with Metashape");
        const Element* resolution = calibration->child("resolution");
        if (!resolution) resolution = element.child("resolution");
        if (!resolution) fail(*calibration, "has no <resolution> (nor has its sensor)");
        sensor.width = pixels(*resolution, "width"), sensor.height = pixels(*resolution, "height");
        const auto value = [&](const char* name) {
            const Element* child = calibration->child(name);
            return child ? number(*child) : 0.0;
        };
        const Element* f = calibration->child("f");
        if (!f) fail(*calibration, "has no <f>");
        std::vector<std::pair<std::string, double>> distortion;
        for (const char* name : {"k1", "k2", "k3", "k4", "p1", "p2", "p3", "p4"}) distortion.emplace_back(name, value(name));
        sensor.refusal = distortionRefusal(where, "frame", distortion);
        const double focal = number(*f), b1 = value("b1"), b2 = value("b2");
        const double k[3][3] = {{focal + b1, b2, sensor.width / 2.0 + value("cx")},
                                {0, focal, sensor.height / 2.0 + value("cy")},
                                {0, 0, 1}};
        try {
            sensor.intrinsics = PinholeIntrinsics::fromK(k, 0.5, "calibration (f + b1, b2, f, W/2 + cx, H/2 + cy)");
        } catch (const Error& e) {
            if (sensor.refusal.empty()) sensor.refusal = where + ": " + e.what();
        }
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
            spec.projection = k.intrinsics.projection(kPlaceholderNear, kPlaceholderFar, "calibration");
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
        f.files = "Agisoft Metashape's XML camera export: frame sensors, each camera's camera-to-chunk transform and "
                  "the chunk's (disabled cameras skipped)";
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
