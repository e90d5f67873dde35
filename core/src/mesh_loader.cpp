#include "zcheck/mesh_loader.h"

#include "zcheck/error.h"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace zcheck {

namespace {

// PLY files that store triangle strips (`element tristrips` with a `vertex_indices` list,
// −1 restarting a strip) are read here: assimp 5.2 reads such a file as a single triangle
// without complaint. ASCII and binary (either byte order) are supported; a malformed file
// is refused with the reason.
class PlyStripReader {
public:
    explicit PlyStripReader(const std::string& path) : path_(path), in_(path, std::ios::binary) {}

    static bool storesStrips(const std::string& path)
    {
        // Look only at the first 64 KiB: a header is short, and the file may be anything.
        std::ifstream in(path, std::ios::binary);
        std::string head(65536, '\0');
        in.read(head.data(), std::streamsize(head.size()));
        head.resize(std::size_t(in.gcount()));
        if (head.rfind("ply", 0) != 0) return false;
        const std::size_t end = head.find("end_header");
        return head.find("\nelement tristrips") < end;
    }

    Scene read()
    {
        in_.seekg(0, std::ios::end);
        fileSize_ = static_cast<std::uint64_t>(in_.tellg());
        in_.seekg(0);
        readHeader();
        Scene scene;
        scene.name = path_;
        for (const Element& element : elements_) {
            // Refuse counts the file cannot hold before allocating or looping for them.
            std::uint64_t minimumBytes = 0;
            for (const Property& property : element.properties)
                minimumBytes += ascii_ ? 2 : std::uint64_t(sizeOf(property.isList ? property.countType : property.type));
            if (element.count > 0 && minimumBytes == 0) fail("element '" + element.name + "' has no properties");
            if (minimumBytes > 0 && element.count > remainingBytes() / minimumBytes)
                fail("element '" + element.name + "' declares " + std::to_string(element.count) +
                     " items, more than the file can hold");
            if (element.name == "vertex" && element.count >= 0xFFFFFFFFull) fail("too many vertices");
            for (std::uint64_t item = 0; item < element.count; ++item) {
                glm::vec3 position(0.0f);
                for (const Property& property : element.properties) {
                    if (property.isList) {
                        const double length = value(property.countType);
                        const std::uint64_t itemBytes = ascii_ ? 2 : std::uint64_t(sizeOf(property.type));
                        if (!(length >= 0) || length != std::floor(length) || length > double(remainingBytes() / itemBytes))
                            fail("a list declares " + formatNumber(length) + " entries, more than the file can hold");
                        const bool indices = property.name == "vertex_indices" || property.name == "vertex_index";
                        std::vector<std::int64_t> list;
                        for (std::uint64_t k = 0; k < std::uint64_t(length); ++k) {
                            const double v = value(property.type);  // other lists are read past
                            if (indices) list.push_back(vertexIndex(v, property.type));
                        }
                        if (indices) addPrimitives(scene, element.name, list);
                    } else {
                        const double v = value(property.type);
                        if (element.name == "vertex") {
                            if (property.name == "x") position.x = float(v);
                            if (property.name == "y") position.y = float(v);
                            if (property.name == "z") position.z = float(v);
                        }
                    }
                }
                if (element.name == "vertex") scene.positions.push_back(position);
            }
        }
        for (const auto& t : scene.triangles)
            for (int k = 0; k < 3; ++k)
                if (t[k] >= scene.positions.size()) fail("a vertex index is out of range");
        return scene;
    }

private:
    struct Property {
        std::string name, type, countType;
        bool isList = false;
    };
    struct Element {
        std::string name;
        std::uint64_t count = 0;
        std::vector<Property> properties;
    };

    std::uint64_t remainingBytes()
    {
        const auto position = in_.tellg();
        return position < 0 ? 0 : fileSize_ - std::min(fileSize_, static_cast<std::uint64_t>(position));
    }

    // A vertex index as read: a whole number in [0, 2^32 − 2], or −1 (a strip restart; for
    // unsigned index types the all-ones value is the restart).
    std::int64_t vertexIndex(double v, const std::string& type) const
    {
        if (!std::isfinite(v) || v != std::floor(v)) fail("a vertex index is not a whole number");
        const bool isUnsigned = type[0] == 'u';
        if (isUnsigned && v == std::ldexp(1.0, 8 * sizeOf(type)) - 1) return -1;
        if (v < -1 || v > 4294967294.0) fail("a vertex index is out of range (" + formatNumber(v) + ")");
        return static_cast<std::int64_t>(v);
    }

    [[noreturn]] void fail(const std::string& why) const
    {
        throw Error("cannot load mesh '" + path_ + "': malformed PLY: " + why);
    }

    void readHeader()
    {
        std::string line;
        std::getline(in_, line);
        while (std::getline(in_, line)) {
            if (!line.empty() && line.back() == '\r') line.pop_back();
            std::istringstream words(line);
            std::string keyword;
            words >> keyword;
            if (keyword == "format") {
                std::string format;
                words >> format;
                if (format == "ascii") ascii_ = true;
                else if (format == "binary_big_endian") bigEndian_ = true;
                else if (format != "binary_little_endian") fail("unknown format '" + format + "'");
            } else if (keyword == "element") {
                Element element;
                if (!(words >> element.name >> element.count)) fail("bad element line '" + line + "'");
                elements_.push_back(element);
            } else if (keyword == "property") {
                if (elements_.empty()) fail("a property before any element");
                Property property;
                std::string first;
                words >> first;
                if (first == "list") {
                    property.isList = true;
                    words >> property.countType >> property.type >> property.name;
                    sizeOf(property.countType);
                } else {
                    property.type = first;
                    words >> property.name;
                }
                sizeOf(property.type);
                elements_.back().properties.push_back(property);
            } else if (keyword == "end_header") {
                return;
            } else if (keyword != "comment" && keyword != "obj_info" && !keyword.empty()) {
                fail("unknown header line '" + line + "'");
            }
        }
        fail("no end_header");
    }

    int sizeOf(const std::string& type) const
    {
        if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
        if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
        if (type == "int" || type == "uint" || type == "int32" || type == "uint32" || type == "float" ||
            type == "float32")
            return 4;
        if (type == "double" || type == "float64") return 8;
        fail("unknown property type '" + type + "'");
    }

    double value(const std::string& type)
    {
        if (ascii_) {
            double v;
            if (!(in_ >> v)) fail("the data ends early or holds a non-number");
            return v;
        }
        unsigned char bytes[8];
        const int size = sizeOf(type);
        if (!in_.read(reinterpret_cast<char*>(bytes), size)) fail("the data ends early");
        if (bigEndian_) std::reverse(bytes, bytes + size);
        auto as = [&](auto v) {
            std::memcpy(&v, bytes, sizeof v);
            return double(v);
        };
        if (type == "char" || type == "int8") return as(std::int8_t{});
        if (type == "uchar" || type == "uint8") return as(std::uint8_t{});
        if (type == "short" || type == "int16") return as(std::int16_t{});
        if (type == "ushort" || type == "uint16") return as(std::uint16_t{});
        if (type == "int" || type == "int32") return as(std::int32_t{});
        if (type == "uint" || type == "uint32") return as(std::uint32_t{});
        if (type == "float" || type == "float32") return as(float{});
        return as(double{});
    }

    // Faces are fans; strips alternate winding and restart at −1. Triangles that repeat an
    // index (the joins between strips) have no area and are not geometry: they are skipped.
    static void addPrimitives(Scene& scene, const std::string& element, const std::vector<std::int64_t>& list)
    {
        auto add = [&](std::int64_t a, std::int64_t b, std::int64_t c) {
            if (a < 0 || b < 0 || c < 0 || a == b || b == c || a == c) return;
            scene.triangles.push_back({std::uint32_t(a), std::uint32_t(b), std::uint32_t(c)});
        };
        if (element == "tristrips") {
            std::size_t start = 0;
            for (std::size_t k = 0; k <= list.size(); ++k) {
                if (k < list.size() && list[k] >= 0) continue;
                for (std::size_t i = start; i + 2 < k; ++i) {
                    const bool even = (i - start) % 2 == 0;
                    add(list[even ? i : i + 1], list[even ? i + 1 : i], list[i + 2]);
                }
                start = k + 1;
            }
        } else {
            for (std::size_t i = 1; i + 1 < list.size(); ++i) add(list[0], list[i], list[i + 1]);
        }
    }

    std::string path_;
    std::ifstream in_;
    std::vector<Element> elements_;
    bool ascii_ = false, bigEndian_ = false;
    std::uint64_t fileSize_ = 0;
};

Scene framed(Scene scene);

}  // namespace

Scene loadMesh(const std::string& path)
{
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw Error("cannot read mesh '" + path + "': no such file");
    if (std::filesystem::is_directory(path, ec)) throw Error("cannot read mesh '" + path + "': it is a directory");
    if (!std::filesystem::is_regular_file(path, ec)) throw Error("cannot read mesh '" + path + "': not a regular file");

    if (PlyStripReader::storesStrips(path)) return framed(PlyStripReader(path).read());

    Assimp::Importer importer;
    // Keep every triangle: no degenerate removal, no validation that drops faces.
    const aiScene* imported = importer.ReadFile(
        path, aiProcess_Triangulate | aiProcess_PreTransformVertices | aiProcess_SortByPType);
    if (!imported || !imported->mRootNode || (imported->mFlags & AI_SCENE_FLAGS_INCOMPLETE)) {
        std::string reason = importer.GetErrorString();
        if (reason.empty()) reason = "unsupported or malformed file";
        for (char& c : reason)
            if (c == '\n' || c == '\r') c = ' ';
        throw Error("cannot load mesh '" + path + "': " + reason);
    }

    Scene scene;
    scene.name = path;
    for (unsigned m = 0; m < imported->mNumMeshes; ++m) {
        const aiMesh* mesh = imported->mMeshes[m];
        if (!(mesh->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
        std::vector<glm::vec3> positions(mesh->mNumVertices);
        for (unsigned v = 0; v < mesh->mNumVertices; ++v)
            positions[v] = {mesh->mVertices[v].x, mesh->mVertices[v].y, mesh->mVertices[v].z};
        std::vector<glm::uvec3> triangles;
        triangles.reserve(mesh->mNumFaces);
        for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
            const aiFace& face = mesh->mFaces[f];
            if (face.mNumIndices == 3) triangles.push_back({face.mIndices[0], face.mIndices[1], face.mIndices[2]});
        }
        scene.append(positions, triangles);
    }
    return framed(std::move(scene));
}

namespace {
// Validates a loaded mesh and gives it a camera that frames its bounding sphere.
Scene framed(Scene scene)
{
    if (scene.triangles.empty()) throw Error("cannot load mesh '" + scene.name + "': it holds no triangles");
    validateScene(scene);
    const glm::dvec3 lo = scene.boundsMin(), hi = scene.boundsMax();
    const double radius = std::max(glm::length(hi - lo) / 2, 1e-6);
    scene.defaultCamera = framingCameraSpec((lo + hi) / 2.0, radius);
    return scene;
}
}  // namespace

Scene loadScene(const std::string& nameOrPath)
{
    if (nameOrPath.empty()) throw Error("the scene name is empty");
    if (isBuiltinSceneName(nameOrPath)) return builtinScene(nameOrPath);
    return loadMesh(nameOrPath);
}

}  // namespace zcheck
