// zcheck's own mesh readers (mesh_formats.h): hand-written files with hand-computed
// triangles, the same mesh in every encoding, the shared models' published counts, and one
// regression per file that used to crash or hang zcheck through assimp.
#include "zcheck/error.h"
#include "zcheck/mesh_formats.h"
#include "zcheck/mesh_loader.h"
#include "zcheck/scene.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <unistd.h>
#include <fstream>
#include <string>

using namespace zcheck;

namespace {

std::string ply(const std::string& format, const std::string& elements)
{
    return "ply\nformat " + format + " 1.0\ncomment test\n" + elements + "end_header\n";
}

template <class T>
void put(std::string& out, T value, bool bigEndian = false)
{
    char raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    if (bigEndian) std::reverse(raw, raw + sizeof(T));
    out.append(raw, sizeof(T));
}

// The unit square in z = 0 with its two triangles (0,1,2) and (0,2,3), in every PLY encoding.
const std::vector<glm::vec3> kSquare = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
const std::vector<glm::uvec3> kSquareFan = {{0, 1, 2}, {0, 2, 3}};

std::string binarySquare(bool bigEndian)
{
    // z is declared first and an extra property sits between them: any order must read.
    std::string out = ply(bigEndian ? "binary_big_endian" : "binary_little_endian",
                          "element vertex 4\nproperty double z\nproperty float x\nproperty uchar red\nproperty float y\n"
                          "element face 1\nproperty list uchar uint vertex_indices\nelement edge 1\nproperty int a\n");
    for (const auto& p : kSquare) {
        put(out, double(p.z), bigEndian);
        put(out, p.x, bigEndian);
        put(out, std::uint8_t(255), bigEndian);
        put(out, p.y, bigEndian);
    }
    put(out, std::uint8_t(4), bigEndian);
    for (std::uint32_t i : {0u, 1u, 2u, 3u}) put(out, i, bigEndian);
    put(out, std::int32_t(7), bigEndian);
    return out;
}

void requireSquare(const Scene& scene)
{
    REQUIRE(scene.positions == kSquare);
    REQUIRE(scene.triangles == kSquareFan);
}

}  // namespace

TEST_CASE("PLY: ascii, binary little- and big-endian give the same triangles, in any property order", "[mesh][ply]")
{
    requireSquare(readPly("a.ply", ply("ascii", "element vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                                                "element face 1\nproperty list uchar int vertex_indices\n") +
                                           "0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n"));
    requireSquare(readPly("le.ply", binarySquare(false)));
    requireSquare(readPly("be.ply", binarySquare(true)));
    // CRLF line ends, blank lines between items and no newline after the last one.
    requireSquare(readPly("crlf.ply", "ply\r\nformat ascii 1.0\r\nelement vertex 4\r\nproperty float x\r\nproperty float y\r\n"
                                      "property float z\r\nelement face 1\r\nproperty list uchar int vertex_indices\r\n"
                                      "end_header\r\n0 0 0\r\n\r\n1 0 0\r\n1 1 0\r\n0 1 0\r\n4 0 1 2 3"));
}

TEST_CASE("PLY: malformed files are refused with the element, the item and the rule", "[mesh][ply]")
{
    const std::string vertex3 = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n";
    const std::string faces = "element face 1\nproperty list uchar int vertex_indices\n";
    auto refused = [](const std::string& bytes, const std::string& why) {
        REQUIRE_THROWS_WITH(readPly("m.ply", bytes), Catch::Contains("'m.ply'") && Catch::Contains(why));
    };
    refused(ply("ascii", vertex3 + faces) + "0 0 0\n1 0 0\n0 1\n3 0 1 2\n", "vertex 2: the line holds fewer values");
    refused(ply("ascii", vertex3 + faces) + "0 0 0\n1 0 0\n0 1 0 5\n3 0 1 2\n", "vertex 2: the line holds more values");
    refused(ply("ascii", vertex3 + faces) + "0 0 0\n1 0 0\n0 1 0\n", "element 'face' declares 1 items, more than the remaining 0");
    refused(ply("ascii", vertex3 + faces) + "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", "refers to vertex 3 but the file has 3");
    refused(ply("ascii", vertex3 + faces) + "0 0 0\n1 0 0\n0 1 0\n2 0 1\n", "at least 3 vertices");
    refused(ply("ascii", vertex3 + faces) + "0 0 0\n1 0 x\n0 1 0\n3 0 1 2\n", "is not a number");
    refused(ply("ascii", "element vertex 3\nproperty float x\nproperty float y\n" + faces) + "0 0\n1 0\n0 1\n3 0 1 2\n",
            "no 'z' property");
    refused("ply\nformat binary_big_", "no end_header");
    refused("ply\nformat ascii 1.0\nelement vertex 3\n", "no end_header");
    refused(ply("binary_little_endian", "element vertex 2000000000\nproperty float x\nproperty float y\nproperty float z\n"),
            "declares 2000000000 items, more than the remaining 0 bytes");
    refused(ply("ascii", vertex3 + "property float y\n" + faces), "property 'y' appears twice");
    refused(ply("ascii", vertex3 + "element face 1\nproperty list float int vertex_indices\n"), "integer type");
    refused(ply("ascii", vertex3 + "flavour sweet\n"), "unknown header keyword");
    refused("plyx\nformat ascii 1.0\nend_header\n", "not a PLY file");
    refused(ply("ascii", vertex3 + faces) + "1e39 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "not a finite binary32");
}

TEST_CASE("regression: assimp crashed on a binary PLY with truncated vertex data or a face list longer than the data",
          "[mesh][ply][regression]")
{
    std::string truncated = binarySquare(false);
    truncated.resize(truncated.size() - 30);  // inside the vertex data
    REQUIRE_THROWS_WITH(readPly("t.ply", truncated), Catch::Contains("ends early") || Catch::Contains("more than the"));
    std::string longList = binarySquare(false);
    longList.resize(longList.size() - 4);
    REQUIRE_THROWS_WITH(readPly("l.ply", longList), Catch::Contains("ends early") || Catch::Contains("more than the"));
}

TEST_CASE("OBJ: polygons become fans, a concave quad is split at its reflex corner, every index form reads", "[mesh][obj]")
{
    const Scene square = readObj("s.obj", "# a square\nv 0 0 0\nv 1 0 0\nv 1 1 0 1.0\nv 0 1 0 0.5 0.5 0.5\nvt 0 0\nvn 0 0 1\n"
                                          "o square\ng face\nusemtl red\ns off\nf 1/1/1 2//1 3/1 -1\n");
    requireSquare(square);
    // A dart: corner 2 (index 2, at (1, 0.2)) is reflex; splitting there keeps both
    // triangles inside the quad: (2,3,0) and (2,0,1).
    const Scene dart = readObj("d.obj", "v 0 0 0\nv 2 0 0\nv 1 0.2 0\nv 1 2 0\nf 1 2 3 4\n");
    REQUIRE(dart.triangles == std::vector<glm::uvec3>{{2, 3, 0}, {2, 0, 1}});
    // A statement continued on the next line.
    REQUIRE(readObj("c.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 \\\n 3\n").triangles.size() == 1);
}

TEST_CASE("OBJ: malformed files are refused with the line and the rule", "[mesh][obj]")
{
    auto refused = [](const std::string& bytes, const std::string& why) {
        REQUIRE_THROWS_WITH(readObj("m.obj", bytes), Catch::Contains("'m.obj'") && Catch::Contains(why));
    };
    refused("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n", "line 4: vertex index 0 is out of range");
    refused("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", "refers to vertex 9 but the file defines 3");
    refused("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n", "vertex index -4 is out of range");
    refused("v 0 0\n", "line 1: a vertex needs x, y and z");
    refused("v 0 0 zero\n", "'zero' is not a number");
    refused("v 0 0 1e400\n", "beyond the range");
    refused("v 0 0 1e39\n", "not a finite binary32");
    refused("\x89PNG\r\n", "unknown statement");
    refused("v 0 0 0\nf 1 1\n", "at least 3 vertices");
}

TEST_CASE("STL: ascii and binary give the same triangles, the binary size must match its count", "[mesh][stl]")
{
    const std::string ascii = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 0\nendloop\n"
                              "endfacet\nendsolid t\n";
    std::string binary(80, ' ');
    binary.replace(0, 5, "solid");  // binary files may begin with "solid" too
    put(binary, std::uint32_t(1));
    for (float v : {0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 1.f, 1.f, 0.f}) put(binary, v);
    put(binary, std::uint16_t(0));
    const Scene a = readStl("a.stl", ascii), b = readStl("b.stl", binary);
    REQUIRE(a.positions == std::vector<glm::vec3>{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}});
    REQUIRE(a.positions == b.positions);
    REQUIRE(a.triangles == b.triangles);
    REQUIRE_THROWS_WITH(readStl("s.stl", binary + "x"), Catch::Contains("declares 1 triangles (134 bytes)"));
    REQUIRE_THROWS_WITH(readStl("l.stl", "solid t\nouter loop\nvertex 0 0 0\nendloop\n"), Catch::Contains("exactly 3"));
}

TEST_CASE("the shared models load with the triangle counts their sources publish", "[mesh][models]")
{
    const std::string dir = ZCHECK_MODELS_DIR;
    // Triangles after fans: beast and suzanne have quads (counted by hand from their f lines).
    for (auto [file, triangles] : {std::pair{"stanford-bunny.obj", 69451}, {"nefertiti.obj", 99938},
                                   {"fandisk.obj", 12946}, {"spot.obj", 5856}, {"cow.obj", 5804}, {"teapot.obj", 6320}}) {
        INFO(file);
        REQUIRE(loadMesh(dir + "/" + file).triangleCount() == std::size_t(triangles));
    }
    REQUIRE(loadMesh(dir + "/suzanne.obj").triangleCount() == 468 * 2 + 32);  // 468 quads, 32 triangles
    REQUIRE(loadMesh(dir + "/igea.ply").positions.size() == 134345);
}

TEST_CASE("a mesh whose triangles all have zero area is refused", "[mesh]")
{
    const std::string path =
        (std::filesystem::temp_directory_path() / ("zcheck-degenerate-" + std::to_string(::getpid()) + ".obj")).string();
    {
        std::ofstream out(path);
        out << "v 0 0 0\nv 1 1 1\nv 2 2 2\nf 1 2 3\n";
    }
    REQUIRE_THROWS_WITH(loadMesh(path), Catch::Contains("degenerate (zero area)"));
    std::remove(path.c_str());
}

TEST_CASE("regression: a PLY face repeating one vertex was dropped silently, so the message blamed an empty file",
          "[mesh][ply][regression]")
{
    const std::string header = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n";
    const Scene faces = readPly("f.ply", ply("ascii", header + "element face 1\nproperty list uchar int vertex_indices\n") +
                                             "0 0 0\n1 0 0\n0 1 0\n3 1 1 1\n");
    REQUIRE(faces.triangles == std::vector<glm::uvec3>{{1, 1, 1}});  // kept as the file gives it: loadMesh judges it
    REQUIRE_THROWS_WITH(
        readPly("s.ply", ply("ascii", header + "element tristrips 1\nproperty list int int vertex_indices\n") +
                             "0 0 0\n1 0 0\n0 1 0\n4 0 0 0 0\n"),
        Catch::Contains("all 2 triangles of its strips repeat a vertex index (degenerate, zero area)"));
}

TEST_CASE("PLY faces are fans and strips restart their alternating winding at each restart", "[mesh][ply]")
{
    // Indices are assembled as they are read (a strip of millions of indices is never copied):
    // the fan keeps its first vertex, a strip's parity counts from its last restart, and a
    // face with fewer than 3 vertices is refused after its list.
    const std::string header = "element vertex 5\nproperty float x\nproperty float y\nproperty float z\n";
    const std::string vertices = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 1.5 0\n";
    const Scene fan = readPly("f.ply", ply("ascii", header + "element face 1\nproperty list uchar int vertex_indices\n") +
                                           vertices + "5 0 1 2 4 3\n");
    REQUIRE(fan.triangles == std::vector<glm::uvec3>{{0, 1, 2}, {0, 2, 4}, {0, 4, 3}});
    const Scene strips = readPly("s.ply", ply("ascii", header + "element tristrips 1\nproperty list int int vertex_indices\n") +
                                              vertices + "11 0 1 2 -1 1 2 3 4 -1 3 3\n");
    // (0,1,2); restart: (1,2,3) even, (3,2,4) odd; restart: 3 3 makes no triangle.
    REQUIRE(strips.triangles == std::vector<glm::uvec3>{{0, 1, 2}, {1, 2, 3}, {3, 2, 4}});
    REQUIRE_THROWS_WITH(readPly("t.ply", ply("ascii", header + "element face 1\nproperty list uchar int vertex_indices\n") +
                                             vertices + "2 0 1\n"),
                        Catch::Contains("face 0: a face needs at least 3 vertices, this one has 2"));
}

TEST_CASE("polygons of more than 3 corners: non-planar ones are counted and measured for the warning", "[mesh]")
{
    // A saddle quad: corners at heights 0, h, 0, h. Newell's normal is +z, the centroid at h/2,
    // so every corner is h/2 off the plane; the size is the diagonal √2: h/(2√2) relative.
    const double h = 0.1, expected = h / (2 * std::sqrt(2.0));
    const std::string saddle = "v 0 0 0\nv 1 0 0.1\nv 1 1 0\nv 0 1 0.1\n";
    const Scene quad = readObj("q.obj", saddle + "f 1 2 3 4\n");
    REQUIRE(quad.planarity.polygons == 1);
    REQUIRE(quad.planarity.nonPlanar == 1);
    REQUIRE(quad.planarity.worst == Approx(expected).epsilon(1e-6));
    REQUIRE_THAT(quad.planarity.warning("q.obj"),
                 Catch::Contains("mesh 'q.obj': 1 of its 1 polygons of more than 3 corners are not planar") &&
                     Catch::Contains("3.54 %") && Catch::Contains("triangulate the mesh before rendering"));
    // The same as a PLY face; triangles and planar polygons are not counted or are planar.
    const std::string header = "element vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                               "element face 1\nproperty list uchar int vertex_indices\n";
    const Scene plyQuad = readPly("q.ply", ply("ascii", header) + "0 0 0\n1 0 0.1\n1 1 0\n0 1 0.1\n4 0 1 2 3\n");
    REQUIRE(plyQuad.planarity.nonPlanar == 1);
    REQUIRE(plyQuad.planarity.worst == Approx(expected).epsilon(1e-6));
    const Scene flat = readObj("f.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 1.5 0\nf 1 2 3 4 5\nf 1 2 3\n");
    REQUIRE(flat.planarity.polygons == 1);
    REQUIRE(flat.planarity.nonPlanar == 0);
    REQUIRE(flat.planarity.warning("f.obj").empty());
}

TEST_CASE("regression: a planar polygon far from the origin was called non-planar, measured after binary32 moved its corners",
          "[mesh][regression]")
{
    // A quad, not aligned with the axes, on the plane z = (x − 512000)/2 + (y − 4212000)/4: every
    // coordinate a multiple of 1/32, so the file's corners lie on it exactly. Binary32 steps by
    // 0.5 at y ≈ 4.2e6 and moves the corners' y by +1/8, +1/8, −1/8 and 0: so rounded, they lie
    // 8.2e-5 of the quad's size off one plane (numpy, by the Newell plane below), over the
    // threshold of 1e-5; as the file holds them, on it.
    const char* const corners[] = {"512300.125 4212340.375 235.15625", "512360.625 4212345.875 266.78125",
                                   "512355.375 4212390.125 275.21875", "512296.875 4212384.5 244.5625"};
    std::string objText, plyVertices;
    for (const std::string corner : corners) {
        objText += "v " + corner + "\n";
        plyVertices += corner + "\n";
    }
    const Scene quad = frameScene(readObj("utm_quad.obj", objText + "f 1 2 3 4\n"), "utm_quad.obj");
    REQUIRE(quad.heldAboutOrigin());  // binary32's move was material: the case this is about
    REQUIRE(quad.planarity.polygons == 1);
    REQUIRE(quad.planarity.nonPlanar == 0);
    REQUIRE(quad.planarity.warning("utm_quad.obj").empty());
    // The same quad as a PLY face of doubles (the readers share the measure).
    const std::string header = "element vertex 4\nproperty double x\nproperty double y\nproperty double z\n"
                               "element face 1\nproperty list uchar int vertex_indices\n";
    const Scene plyQuad = readPly("utm_quad.ply", ply("ascii", header) + plyVertices + "4 0 1 2 3\n");
    REQUIRE(plyQuad.planarity.polygons == 1);
    REQUIRE(plyQuad.planarity.nonPlanar == 0);
    // A saddle there is still one, measured as near the origin: corners h off in turn, 1 apart.
    const double h = 0.1, expected = h / (2 * std::sqrt(2.0));
    const Scene saddle = readObj("utm_saddle.obj", "v 512000.3 4212000.3 100\nv 512001.3 4212000.3 100.1\n"
                                                   "v 512001.3 4212001.3 100\nv 512000.3 4212001.3 100.1\nf 1 2 3 4\n");
    REQUIRE(saddle.planarity.nonPlanar == 1);
    REQUIRE(saddle.planarity.worst == Approx(expected).epsilon(1e-6));
}

TEST_CASE("regression: a mesh in UTM coordinates was rounded to binary32 without a word", "[mesh][regression]")
{
    // (512345.678, 4212345.321, 123.4) as binary32: x to a sixteenth (512345.6875, 0.0095 off),
    // y to a half (4212345.5, 0.179 off), z by ~3e-6: the vertex moves by ~0.1793 of a mesh 1.41
    // across, which is no longer the file's mesh. The mesh is now held about a local origin
    // instead (the regression "a correct map of a mesh in UTM coordinates was judged against the
    // mesh rounded to binary32"), and the reports say what binary32 at the file's coordinates does.
    const double moved = std::hypot(512345.6875 - 512345.678, 4212345.5 - 4212345.321, double(123.4f) - 123.4);
    const glm::dvec3 file[3] = {{512345.678, 4212345.321, 123.4}, {512346.678, 4212345.321, 123.4}, {512345.678, 4212346.321, 123.4}};
    auto requireMaterial = [&](Scene scene, const std::string& mesh) {
        INFO(mesh);
        REQUIRE(scene.rounding.largestMove == Approx(moved).epsilon(1e-6));
        scene = frameScene(std::move(scene), "cannot load mesh '" + mesh + "'");
        REQUIRE(scene.rounding.size == Approx(std::sqrt(2.0)).epsilon(0.01));
        REQUIRE(scene.rounding.material());
        // The centre of the box (512346.178, 4212345.821, 123.4) on the grid of 1 (the power of
        // two at or below the size, 1.41): (512346, 4212346, 123).
        REQUIRE(scene.origin == glm::dvec3(512346, 4212346, 123));
        // Each vertex, in the world, is the file's to binary32 of the mesh's own size (2^-24 of
        // coordinates under 1.5 about the origin), not to the 0.5 steps at 4.2e6.
        for (int v = 0; v < 3; ++v) REQUIRE(glm::length(scene.worldPosition(v) - file[v]) < 1e-7);
        REQUIRE(scene.rounding.residual.empty());  // freed once placed
        // Framed again (a copy, a pickle), it stays where it is held.
        const Scene again = frameScene(scene, "again");
        REQUIRE(again.origin == scene.origin);
        REQUIRE(again.positions == scene.positions);
        const std::string warning = scene.rounding.warning(mesh, scene.origin);
        REQUIRE_THAT(warning, Catch::StartsWith("mesh '" + mesh + "': far from the origin, held about (512346, 4212346, 123)"));
        REQUIRE_THAT(warning, Catch::Contains("its vertices moved by up to 0.1793"));
        REQUIRE_THAT(warning, Catch::Contains("coordinates up to 4.212e+06, where binary32 steps by 0.5"));
        REQUIRE_THAT(warning, Catch::Contains("a map rendered so shows another mesh"));
        // The default camera frames it in the world.
        REQUIRE(glm::length(scene.defaultCamera.view.target - glm::dvec3(512346.178, 4212345.821, 123.4)) < 1e-3);
    };
    const std::string obj = "v 512345.678 4212345.321 123.4\nv 512346.678 4212345.321 123.4\nv 512345.678 4212346.321 123.4\nf 1 2 3\n";
    requireMaterial(readObj("utm.obj", obj), "utm.obj");
    requireMaterial(readStl("utm.stl", "solid t\nfacet normal 0 0 1\nouter loop\nvertex 512345.678 4212345.321 123.4\n"
                                       "vertex 512346.678 4212345.321 123.4\nvertex 512345.678 4212346.321 123.4\nendloop\nendfacet\n"
                                       "endsolid t\n"),
                    "utm.stl");
    // The UTM triangle as a binary PLY of `Coordinate` (double or float) x, y, z.
    auto binaryPly = [](auto coordinate) {
        using Coordinate = decltype(coordinate);
        const std::string type = sizeof(Coordinate) == 8 ? "double" : "float";
        std::string out = ply("binary_little_endian", "element vertex 3\nproperty " + type + " x\nproperty " + type +
                                                          " y\nproperty " + type + " z\nelement face 1\n"
                                                          "property list uchar int vertex_indices\n");
        for (const glm::dvec3 p : {glm::dvec3(512345.678, 4212345.321, 123.4), glm::dvec3(512346.678, 4212345.321, 123.4),
                                   glm::dvec3(512345.678, 4212346.321, 123.4)})
            put(out, Coordinate(p.x)), put(out, Coordinate(p.y)), put(out, Coordinate(p.z));
        put(out, std::uint8_t(3)), put(out, 0), put(out, 1), put(out, 2);
        return out;
    };
    const std::string doubles = binaryPly(0.0);
    requireMaterial(readPly("utm.ply", doubles), "utm.ply");
    // A glTF's binary32 triangle placed in UTM coordinates by its node (applied in binary64).
    const std::string gltf = R"({"asset": {"version": "2.0"},
        "buffers": [{"byteLength": 44, "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIAAAA="}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
                      {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "nodes": [{"mesh": 0, "translation": [512345.678, 4212345.321, 123.4]}],
        "scenes": [{"nodes": [0]}], "scene": 0})";
    requireMaterial(readGltf("utm.gltf", gltf), "utm.gltf");

    // Digits like those a few sizes from the origin, and UTM coordinates a file already holds in binary32 (a
    // float PLY: every reader gets the same mesh), are no news.
    Scene near = frameScene(readObj("near.obj", "v 1.678 2.321 3.4\nv 2.678 2.321 3.4\nv 1.678 3.321 3.4\nf 1 2 3\n"), "near");
    REQUIRE(near.rounding.largestMove > 0);
    REQUIRE_FALSE(near.rounding.material());
    REQUIRE(near.rounding.warning("near.obj").empty());
    REQUIRE_FALSE(near.heldAboutOrigin());
    const Scene stored = frameScene(readPly("f.ply", binaryPly(0.0f)), "f");
    REQUIRE(stored.rounding.largestMove == 0);
    REQUIRE(stored.rounding.warning("f.ply").empty());
    REQUIRE_FALSE(stored.heldAboutOrigin());

    // Coordinates whose binary32 steps swallow the whole mesh (8 at 1e8) were refused as
    // degenerate; about its own origin the triangle keeps its area.
    const Scene far = frameScene(readObj("far.obj", "v 1e8 1e8 0\nv 100000000.5 1e8 0\nv 1e8 100000000.5 0\nf 1 2 3\n"),
                                 "cannot load mesh 'far.obj'");
    REQUIRE(far.heldAboutOrigin());
    REQUIRE(far.worldPosition(1) == glm::dvec3(100000000.5, 1e8, 0));
    REQUIRE_THAT(far.rounding.warning("far.obj", far.origin), Catch::Contains("where binary32 steps by 8"));
    // A scene put together without its file's coordinates (no reader stored them) cannot be
    // placed: collapsed, it is still refused with the reason.
    Scene collapsed = far;
    collapsed.origin = glm::dvec3(0.0);
    for (glm::vec3& p : collapsed.positions) p = glm::vec3(1e8f, 1e8f, 0.0f);  // as binary32 holds the file's
    REQUIRE(collapsed.rounding.residual.empty());  // nothing kept of the file's coordinates
    REQUIRE_THROWS_WITH(frameScene(collapsed, "cannot load mesh 'far.obj'"),
                        Catch::Contains("degenerate") && Catch::Contains("where binary32 steps by 8") &&
                            Catch::Contains("move the mesh near the origin"));
}

TEST_CASE("validateScene names the first offending vertex or index in order, however large the scene", "[mesh][scene]")
{
    // 300,000 vertices and triangles: the search runs in parallel parts (65,536 elements each), and
    // the message must still be the first offender's, in order, not whichever part finished first.
    Scene scene;
    scene.name = "big";
    const std::size_t n = 300000;
    for (std::size_t i = 0; i < n; ++i) scene.positions.push_back(glm::vec3(float(i % 1000), float(i / 1000), 0.0f));
    for (std::size_t i = 0; i + 2 < n; ++i)
        scene.triangles.push_back(glm::uvec3(std::uint32_t(i), std::uint32_t(i + 1), std::uint32_t(i + 2)));
    REQUIRE_NOTHROW(validateScene(scene));

    Scene vertices = scene;
    vertices.positions[250000].y = 1e16f;              // later
    vertices.positions[70000].z = std::nanf("");       // first
    REQUIRE_THROWS_WITH(validateScene(vertices), "scene 'big' has a vertex that is not finite");
    vertices.positions[70000].z = 0.0f;
    vertices.positions[250000].x = INFINITY;           // the same vertex's first bad coordinate: x
    REQUIRE_THROWS_WITH(validateScene(vertices), "scene 'big' has a vertex that is not finite");
    vertices.positions[250000].x = 0.0f;
    REQUIRE_THROWS_WITH(validateScene(vertices),
                        Catch::StartsWith("scene 'big' has a vertex coordinate 1") && Catch::Contains("beyond the ±1e15"));
    vertices.positions[250000].y = -1e15f;             // at the bound: allowed
    REQUIRE_NOTHROW(validateScene(vertices));

    Scene indices = scene;
    indices.triangles[280000][0] = 400000;             // later
    indices.triangles[131072][2] = 300000;             // first: the first element of a part
    REQUIRE_THROWS_WITH(validateScene(indices), "scene 'big' has a vertex index out of range (300000)");
    indices.triangles[131072][2] = 131074;
    REQUIRE_THROWS_WITH(validateScene(indices), "scene 'big' has a vertex index out of range (400000)");
}
