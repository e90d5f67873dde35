// The YAML and XML readers of calibration files (yaml_lite.h, xml_lite.h) against the forms
// real writers produce: OpenCV FileStorage (YAML and XML, old and new), ROS
// camera_calibration_parsers files, and CameraInfo messages as `rostopic echo` (ROS 1) and
// `ros2 topic echo` print them. Then every refusal: each must be a zcheck::Error naming the
// source, the line and the rule.
#include "zcheck/detail/xml_lite.h"
#include "zcheck/detail/yaml_lite.h"

#include "zcheck/error.h"

#include <catch2/catch.hpp>

#include <string>
#include <vector>

using namespace zcheck;

namespace {

const std::string kYamlSource = "camera file 'calib.yml'";
const std::string kXmlSource = "camera file 'calib.xml'";

// The scalars of a sequence, in order.
std::vector<std::string> scalars(const yaml::Node& sequence)
{
    std::vector<std::string> out;
    for (const yaml::Node& item : sequence.items) out.push_back(item.scalar);
    return out;
}

const yaml::Node& at(const yaml::Node& map, const std::string& key)
{
    const yaml::Node* node = map.find(key);
    INFO("key " << key);
    REQUIRE(node != nullptr);
    return *node;
}

const xml::Element& childOf(const xml::Element& element, const std::string& name)
{
    const xml::Element* found = element.child(name);
    INFO("element " << name);
    REQUIRE(found != nullptr);
    return *found;
}

std::string yamlMessage(const std::string& text)
{
    try {
        yaml::parse(text, kYamlSource);
    } catch (const Error& e) {
        return e.what();
    }
    return "(parsed without an error)";
}

std::string xmlMessage(const std::string& text)
{
    try {
        xml::parse(text, kXmlSource);
    } catch (const Error& e) {
        return e.what();
    }
    return "(parsed without an error)";
}

// Other exception types escape and fail the test: only zcheck::Error is a refusal.
void checkYamlRefused(const std::string& text, int line, const std::string& rule)
{
    INFO("YAML text:\n" << text);
    const std::string message = yamlMessage(text);
    CHECK_THAT(message, Catch::StartsWith(kYamlSource + ": line " + std::to_string(line) + ": "));
    CHECK_THAT(message, Catch::Contains(rule));
}

void checkXmlRefused(const std::string& text, int line, const std::string& rule)
{
    INFO("XML text:\n" << text);
    const std::string message = xmlMessage(text);
    CHECK_THAT(message, Catch::StartsWith(kXmlSource + ": line " + std::to_string(line) + ": "));
    CHECK_THAT(message, Catch::Contains(rule));
}

// As OpenCV 4 writes it (samples/cpp/tutorial_code/calib3d/camera_calibration).
const std::string kOpenCvYaml = R"(%YAML:1.0
---
calibration_time: "Tue 04 Jul 2023 10:00:00 CEST"
image_width: 640
image_height: 480
flags: 0
camera_matrix: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 6.5746697810243404e+02, 0., 3.1950000000000000e+02, 0.,
       6.5746697810243404e+02, 2.3950000000000000e+02, 0., 0., 1. ]
distortion_coefficients: !!opencv-matrix
   rows: 5
   cols: 1
   dt: d
   data: [ -4.1802327018241026e-01, 5.0715243805833121e-01, 0., 0.,
       -5.7843596847939704e-01 ]
avg_reprojection_error: 3.9251389668713869e-01
)";

// OpenCV 2's out_camera_data.yml: no "---", Windows exponents, a comment line, a quoted dt.
const std::string kOldOpenCvYaml = R"(%YAML:1.0
calibration_Time: "08/19/11 20:44:38"
nrOfFrames: 8
image_Width: 640
image_Height: 480
square_Size: 50.
# flags:  +fix_aspectRatio +fix_principal_point +zero_tangent_dist
flagValue: 14
Camera_Matrix: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 6.5746697944293521e+002, 0., 3.1950000000000000e+002, 0.,
       6.5746697944293521e+002, 2.3950000000000000e+002, 0., 0., 1. ]
Distortion_Coefficients: !!opencv-matrix
   rows: 5
   cols: 1
   dt: d
   data: [ -4.1802327176423804e-001, 5.0715244063187526e-001, 0., 0.,
       -5.7843597214487474e-001 ]
Image_points: !!opencv-matrix
   rows: 1
   cols: 2
   dt: "2f"
   data: [ 2.35e+002, 1.5e+001, .Nan, -.Inf ]
)";

// camera_calibration_parsers (parse_yml.cpp): plain YAML, no header.
const std::string kRosCalibrationYaml = R"(image_width: 640
image_height: 480
camera_name: narrow_stereo/left
camera_matrix:
  rows: 3
  cols: 3
  data: [525.0, 0.0, 319.5, 0.0, 525.0, 239.5, 0.0, 0.0, 1.0]
distortion_model: plumb_bob
distortion_coefficients:
  rows: 1
  cols: 5
  data: [0.0, 0.0, 0.0, 0.0, 0.0]
rectification_matrix:
  rows: 3
  cols: 3
  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]
projection_matrix:
  rows: 3
  cols: 4
  data: [525.0, 0.0, 319.5, 0.0, 0.0, 525.0, 239.5, 0.0, 0.0, 0.0, 1.0, 0.0]
binning_x: 0
binning_y: 0
roi:
  x_offset: 0
  y_offset: 0
  height: 0
  width: 0
  do_rectify: false
)";

// `ros2 topic echo /camera_info` (PyYAML, default_flow_style=False): block sequences at the
// key's indentation, each message followed by "---".
const std::string kRos2EchoYaml = R"(header:
  stamp:
    sec: 1700000000
    nanosec: 5000
  frame_id: camera_optical
height: 480
width: 640
distortion_model: plumb_bob
d:
- 0.1
- -0.2
- 0.0
- 0.0
- 0.0
k:
- 525.0
- 0.0
- 319.5
- 0.0
- 525.0
- 239.5
- 0.0
- 0.0
- 1.0
r:
- 1.0
- 0.0
- 0.0
- 0.0
- 1.0
- 0.0
- 0.0
- 0.0
- 1.0
p:
- 525.0
- 0.0
- 319.5
- 0.0
- 0.0
- 525.0
- 239.5
- 0.0
- 0.0
- 0.0
- 1.0
- 0.0
binning_x: 0
binning_y: 0
roi:
  x_offset: 0
  y_offset: 0
  height: 0
  width: 0
  do_rectify: false
---
header:
  stamp:
    sec: 1700000001
)";

// `rostopic echo` in ROS 1: flow lists, "key: " with a trailing blank before a block, a quoted
// frame id, Python's True/False.
const std::string kRos1EchoYaml = "header: \n"
                                  "  seq: 42\n"
                                  "  stamp: \n"
                                  "    secs: 1700000000\n"
                                  "    nsecs:         0\n"
                                  "  frame_id: \"camera\"\n"
                                  "height: 480\n"
                                  "width: 640\n"
                                  "distortion_model: \"plumb_bob\"\n"
                                  "D: [0.1, -0.2, 0.0, 0.0, 0.0]\n"
                                  "K: [525.0, 0.0, 319.5, 0.0, 525.0, 239.5, 0.0, 0.0, 1.0]\n"
                                  "R: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]\n"
                                  "P: [525.0, 0.0, 319.5, 0.0, 0.0, 525.0, 239.5, 0.0, 0.0, 0.0, 1.0, 0.0]\n"
                                  "binning_x: 0\n"
                                  "binning_y: 0\n"
                                  "roi: \n"
                                  "  x_offset: 0\n"
                                  "  y_offset: 0\n"
                                  "  height: 0\n"
                                  "  width: 0\n"
                                  "  do_rectify: False\n"
                                  "---\n"
                                  "header: \n"
                                  "  seq: 43\n";

const std::string kOpenCvXml = R"(<?xml version="1.0"?>
<opencv_storage>
<calibration_time>"Tue 04 Jul 2023 10:00:00 CEST"</calibration_time>
<image_width>640</image_width>
<image_height>480</image_height>
<camera_matrix type_id="opencv-matrix">
  <rows>3</rows>
  <cols>3</cols>
  <dt>d</dt>
  <data>
    657.46697810243404 0. 319.5 0. 657.46697810243404 239.5 0. 0. 1.</data></camera_matrix>
<distortion_coefficients type_id="opencv-matrix">
  <rows>5</rows>
  <cols>1</cols>
  <dt>d</dt>
  <data>
    -4.1802327018241026e-01 5.0715243805833121e-01 0. 0.
    -5.7843596847939704e-01</data></distortion_coefficients>
<avg_reprojection_error>3.9251389668713869e-01</avg_reprojection_error>
</opencv_storage>
)";

}  // namespace

TEST_CASE("OpenCV FileStorage YAML reads as a map of tagged matrices whose data wraps over lines", "[io]")
{
    const yaml::Node root = yaml::parse(kOpenCvYaml, kYamlSource);
    REQUIRE(root.kind == yaml::Node::Kind::Map);
    REQUIRE(root.entries.size() == 7);
    CHECK(root.entries[0].first == "calibration_time");
    CHECK(at(root, "calibration_time").scalar == "Tue 04 Jul 2023 10:00:00 CEST");
    CHECK(at(root, "calibration_time").quoted);
    CHECK(at(root, "image_width").scalar == "640");
    CHECK_FALSE(at(root, "image_width").quoted);

    const yaml::Node& cameraMatrix = at(root, "camera_matrix");
    CHECK(cameraMatrix.kind == yaml::Node::Kind::Map);
    CHECK(cameraMatrix.tag == "opencv-matrix");
    CHECK(cameraMatrix.line == 7);
    CHECK(at(cameraMatrix, "rows").scalar == "3");
    CHECK(at(cameraMatrix, "rows").line == 8);
    CHECK(at(cameraMatrix, "dt").scalar == "d");
    const yaml::Node& data = at(cameraMatrix, "data");
    CHECK(data.kind == yaml::Node::Kind::Sequence);
    CHECK(data.line == 11);
    CHECK(scalars(data) == std::vector<std::string>{"6.5746697810243404e+02", "0.", "3.1950000000000000e+02", "0.",
                                                    "6.5746697810243404e+02", "2.3950000000000000e+02", "0.", "0.", "1."});
    CHECK(data.items[4].line == 12);
    CHECK(scalars(at(at(root, "distortion_coefficients"), "data")).size() == 5);
    CHECK(at(root, "avg_reprojection_error").scalar == "3.9251389668713869e-01");
    CHECK(root.find("Camera_Matrix") == nullptr);
    CHECK(root.findIgnoringCase("Camera_Matrix") == &cameraMatrix);
}

TEST_CASE("An old OpenCV file without '---', with Windows line ends, reads the same way", "[io]")
{
    std::string windows;
    for (const char c : kOldOpenCvYaml) windows += c == '\n' ? std::string("\r\n") : std::string(1, c);
    for (const std::string& text : {kOldOpenCvYaml, windows, "\xEF\xBB\xBF" + windows}) {
        const yaml::Node root = yaml::parse(text, kYamlSource);
        CHECK(at(root, "square_Size").scalar == "50.");
        const yaml::Node* cameraMatrix = root.findIgnoringCase("camera_matrix");
        REQUIRE(cameraMatrix != nullptr);
        CHECK(cameraMatrix->tag == "opencv-matrix");
        CHECK(cameraMatrix->line == 9);
        CHECK(scalars(at(*cameraMatrix, "data"))[0] == "6.5746697944293521e+002");
        CHECK(scalars(at(*root.findIgnoringCase("distortion_coefficients"), "data")).back() == "-5.7843597214487474e-001");
        const yaml::Node& points = at(root, "Image_points");
        CHECK(at(points, "dt").scalar == "2f");
        CHECK(at(points, "dt").quoted);
        CHECK(scalars(at(points, "data")) == std::vector<std::string>{"2.35e+002", "1.5e+001", ".Nan", "-.Inf"});
    }
}

TEST_CASE("A camera_calibration_parsers file reads as plain YAML", "[io]")
{
    const yaml::Node root = yaml::parse(kRosCalibrationYaml, kYamlSource);
    CHECK(at(root, "camera_name").scalar == "narrow_stereo/left");
    CHECK(at(root, "distortion_model").scalar == "plumb_bob");
    CHECK(at(at(root, "camera_matrix"), "cols").scalar == "3");
    CHECK(at(at(root, "camera_matrix"), "data").items.size() == 9);
    CHECK(scalars(at(at(root, "rectification_matrix"), "data")) ==
          std::vector<std::string>{"1", "0", "0", "0", "1", "0", "0", "0", "1"});
    CHECK(at(at(root, "projection_matrix"), "data").items.size() == 12);
    CHECK(at(at(root, "roi"), "do_rectify").scalar == "false");
    CHECK(root.entries.back().first == "roi");
}

TEST_CASE("A ros2 topic echo message keeps block sequences at the key's indentation and stops at '---'", "[io]")
{
    const yaml::Node root = yaml::parse(kRos2EchoYaml, kYamlSource);
    CHECK(at(at(at(root, "header"), "stamp"), "sec").scalar == "1700000000");
    CHECK(at(at(root, "header"), "frame_id").scalar == "camera_optical");
    const yaml::Node& d = at(root, "d");
    CHECK(d.kind == yaml::Node::Kind::Sequence);
    CHECK(d.line == 10);
    CHECK(scalars(d) == std::vector<std::string>{"0.1", "-0.2", "0.0", "0.0", "0.0"});
    CHECK(at(root, "k").items.size() == 9);
    CHECK(at(root, "k").items[2].scalar == "319.5");
    CHECK(at(root, "r").items.size() == 9);
    CHECK(at(root, "p").items.size() == 12);
    CHECK(at(root, "binning_x").scalar == "0");
    CHECK(at(at(root, "roi"), "do_rectify").scalar == "false");
    // The second message is not read (its repeated "header" would otherwise be refused).
    CHECK(root.entries.size() == 11);
}

TEST_CASE("A ROS 1 rostopic echo message reads its flow lists and quoted frame id", "[io]")
{
    const yaml::Node root = yaml::parse(kRos1EchoYaml, kYamlSource);
    const yaml::Node& header = at(root, "header");
    CHECK(header.kind == yaml::Node::Kind::Map);
    CHECK(at(header, "seq").scalar == "42");
    CHECK(at(at(header, "stamp"), "nsecs").scalar == "0");
    CHECK(at(header, "frame_id").scalar == "camera");
    CHECK(at(header, "frame_id").quoted);
    CHECK(scalars(at(root, "D")) == std::vector<std::string>{"0.1", "-0.2", "0.0", "0.0", "0.0"});
    CHECK(at(root, "K").items.size() == 9);
    CHECK(at(root, "P").items.size() == 12);
    CHECK(root.find("k") == nullptr);
    CHECK(root.findIgnoringCase("k") == &at(root, "K"));
    CHECK(at(at(root, "roi"), "do_rectify").scalar == "False");
}

TEST_CASE("YAML flow collections nest, span lines and take tags, OpenCV's {x:1} reads as a key and a value", "[io]")
{
    const yaml::Node root = yaml::parse("%YAML 1.2\n"
                                        "---\n"
                                        "m: !!opencv-matrix { rows: 1, cols: 2, dt: d,\n"
                                        "   data: [ 1., 2. ] }\n"
                                        "nested: [ [1, 2], {a: [x, 'y'], \"b\": {}}, [], ]\n"
                                        "features:\n"
                                        "   - { x:167, y:49, lbp:[ 1, 0 ] }\n"
                                        "   - !!point [3, 4]\n"
                                        "url: [http://example.com:80/a]\n"
                                        "empty: {a, b: }\n"
                                        "...\n"
                                        "ignored: [ unterminated\n",
                                        kYamlSource);
    const yaml::Node& m = at(root, "m");
    CHECK(m.tag == "opencv-matrix");
    CHECK(m.kind == yaml::Node::Kind::Map);
    CHECK(m.line == 3);
    CHECK(scalars(at(m, "data")) == std::vector<std::string>{"1.", "2."});
    CHECK(at(m, "data").line == 4);
    const yaml::Node& nested = at(root, "nested");
    REQUIRE(nested.items.size() == 3);
    CHECK(scalars(nested.items[0]) == std::vector<std::string>{"1", "2"});
    CHECK(scalars(at(nested.items[1], "a")) == std::vector<std::string>{"x", "y"});
    CHECK(at(nested.items[1], "a").items[1].quoted);
    CHECK(at(nested.items[1], "b").kind == yaml::Node::Kind::Map);
    CHECK(nested.items[2].kind == yaml::Node::Kind::Sequence);
    CHECK(nested.items[2].items.empty());
    const yaml::Node& features = at(root, "features");
    REQUIRE(features.items.size() == 2);
    CHECK(at(features.items[0], "x").scalar == "167");
    CHECK(scalars(at(features.items[0], "lbp")) == std::vector<std::string>{"1", "0"});
    CHECK(features.items[1].tag == "point");
    CHECK(features.items[1].line == 8);
    CHECK(scalars(at(root, "url")) == std::vector<std::string>{"http://example.com:80/a"});
    CHECK(at(at(root, "empty"), "a").scalar.empty());
    CHECK(at(at(root, "empty"), "b").scalar.empty());
    CHECK(root.find("ignored") == nullptr);
}

TEST_CASE("YAML block sequences hold maps, nested sequences and empty items", "[io]")
{
    const yaml::Node root = yaml::parse("cameras:\n"
                                        "  - name: left\n"
                                        "    k: [1, 2]\n"
                                        "    d:\n"
                                        "    - 0.5\n"
                                        "  - - a\n"
                                        "    - b\n"
                                        "  -\n"
                                        "  - !!opencv-matrix\n"
                                        "    rows: 1\n"
                                        "empty:\n"
                                        "last: ''\n",
                                        kYamlSource);
    const yaml::Node& cameras = at(root, "cameras");
    REQUIRE(cameras.items.size() == 4);
    CHECK(at(cameras.items[0], "name").scalar == "left");
    CHECK(scalars(at(cameras.items[0], "d")) == std::vector<std::string>{"0.5"});
    CHECK(scalars(cameras.items[1]) == std::vector<std::string>{"a", "b"});
    CHECK(cameras.items[2].kind == yaml::Node::Kind::Scalar);
    CHECK(cameras.items[2].scalar.empty());
    CHECK(cameras.items[3].tag == "opencv-matrix");
    CHECK(at(cameras.items[3], "rows").scalar == "1");
    CHECK(at(root, "empty").scalar.empty());
    CHECK_FALSE(at(root, "empty").quoted);
    CHECK(at(root, "empty").line == 11);
    CHECK(at(root, "last").quoted);
}

TEST_CASE("YAML comments count only after whitespace, quoted scalars keep '#' and resolve escapes", "[io]")
{
    const yaml::Node root = yaml::parse("# a calibration\n"
                                        "a: 1 # one\n"
                                        "b: x#y\n"
                                        "c: \"#not a comment\"   # but this is\n"
                                        "d: 'it''s'\n"
                                        "opencv: \"it\\'s \\x41\"\n"
                                        "e: \"tab\\tquote\\\" slash\\/ back\\\\ new\\n \\u00e9\\u20AC\"\n"
                                        "\"quoted key\": [a # inside a flow list\n"
                                        "  , b]\n"
                                        "f: value with  spaces   \n",
                                        kYamlSource);
    CHECK(at(root, "a").scalar == "1");
    CHECK(at(root, "b").scalar == "x#y");
    CHECK(at(root, "c").scalar == "#not a comment");
    CHECK(at(root, "d").scalar == "it's");
    CHECK(at(root, "opencv").scalar == "it's A");  // OpenCV writes \' inside ".."
    CHECK(at(root, "e").scalar == "tab\tquote\" slash/ back\\ new\n \xC3\xA9\xE2\x82\xAC");
    CHECK(scalars(at(root, "quoted key")) == std::vector<std::string>{"a", "b"});
    CHECK(at(root, "f").scalar == "value with  spaces");
}

TEST_CASE("Each YAML refusal is an Error naming the source, the line and the rule", "[io]")
{
    checkYamlRefused("a: 1\nb: &anchor 2\n", 2, "anchors and aliases");
    checkYamlRefused("a: 1\nb: *anchor\n", 2, "anchors and aliases");
    checkYamlRefused("a: 1\n- &x b\n", 2, "'- ' item where a key");
    checkYamlRefused("a: |\n  text\n", 1, "block scalars");
    checkYamlRefused("a: >-\n  text\n", 1, "block scalars");
    checkYamlRefused("a: one\n  two\n", 2, "indented more");
    checkYamlRefused("a: \"one\n  two\"\n", 1, "unterminated double-quoted");
    checkYamlRefused("a: 1\nb: 'it''s\n", 2, "unterminated single-quoted");
    checkYamlRefused("a:\n\tb: 1\n", 2, "tab in the indentation");
    checkYamlRefused("a:\n  - 1\n  -\tb: 2\n", 3, "tab after '-'");
    checkYamlRefused("rows: 3\ncols: 3\nrows: 4\n", 3, "the key 'rows' is repeated (first at line 1)");
    checkYamlRefused("m: {rows: 3,\n  rows: 4}\n", 2, "the key 'rows' is repeated (first at line 1)");
    checkYamlRefused("m:\n  \"rows\": 3\n  rows: 4\n", 3, "'rows' is repeated");
    checkYamlRefused("a: 1\ndata: [1, 2,\n  3\n", 2, "flow sequence opened here is not closed");
    checkYamlRefused("data: {a: 1\n", 1, "flow map opened here is not closed");
    checkYamlRefused("data: [1, 2,\n---\nb: 2\n", 2, "document marker inside the flow sequence opened at line 1");
    checkYamlRefused("data: [1\n  2]\n", 2, "expected ',' or ']'");
    checkYamlRefused("data: [1,, 2]\n", 1, "empty entry");
    checkYamlRefused("data: [a: 1]\n", 1, "key inside a flow sequence");
    checkYamlRefused("a:\n    b: 1\n  c: 2\n", 3, "indented more");
    checkYamlRefused("- 1\n - 2\n", 2, "indented more");
    checkYamlRefused("  a: 1\nb: 2\n", 2, "indented less");
    checkYamlRefused("a:\n  - 1\n  b: 2\n", 3, "expected a '- ' item");
    checkYamlRefused("a: b: c\n", 1, "a map cannot start on the line of a key");
    checkYamlRefused("a: - 1\n", 1, "sequence cannot start on the line of a key");
    checkYamlRefused("just a value\n", 1, "must be a map or a sequence");
    checkYamlRefused("%YAML:1.0\n---\n\"quoted\"\n", 3, "must be a map or a sequence");
    checkYamlRefused("%YAML:1.0\n---\n", 3, "the document is empty");
    checkYamlRefused("", 1, "the document is empty");
    checkYamlRefused("# only a comment\n...\n", 2, "the document is empty");
    checkYamlRefused("a: \"\\q\"\n", 1, "unknown escape");
    checkYamlRefused("a: \"\\u12\"\n", 1, "hex digits");
    checkYamlRefused("a: \"\\ud800\"\n", 1, "not a character");
    checkYamlRefused("a: \"\\0\"\n", 1, "NUL");
    checkYamlRefused("%TAG ! tag:example.com:\n---\na: 1\n", 1, "not supported (only %YAML)");
    checkYamlRefused("%YAML 2.0\na: 1\n", 1, "version '2.0'");
    checkYamlRefused("%YAML 1.2\n%YAML 1.2\n---\na: 1\n", 2, "second %YAML");
    checkYamlRefused("--- {a: 1}\n", 1, "on the '---' line");
    checkYamlRefused("? a\n: b\n", 1, "explicit keys");
    checkYamlRefused("a: !!opencv-matrix !!other\n  rows: 1\n", 1, "second tag");
    checkYamlRefused("a: !<tag:yaml.org,2002:str> b\n", 1, "verbatim tags");
    checkYamlRefused("a: !!int,\n", 1, "must be followed by a space");
    checkYamlRefused("a: \"x\"# c\n", 1, "a comment needs a space");
    checkYamlRefused("a: [x,#c\n]\n", 1, "comment needs a space");
    checkYamlRefused("a: @x\n", 1, "reserved");
    checkYamlRefused("a: 1\nb: caf\xE9\n", 2, "not valid UTF-8");
    checkYamlRefused("a: 1\nb: x\x01y\n", 2, "control character 0x01");
    checkYamlRefused("\xFF\xFE" "a", 1, "UTF-16");
    checkYamlRefused("a: 1\n[b]: 2\n", 2, "flow collection as a key");
    checkYamlRefused("a: 1\nb\n", 2, "expected a key ('name: value') of the map at line 1");
    checkYamlRefused("{a: 1}: 2\n", 1, "unexpected text after the value");
}

TEST_CASE("YAML nesting is limited to 64 levels, in block and in flow form", "[io]")
{
    // The top-level map is the first level.
    const auto flow = [](int levels) {
        return "a: " + std::string(std::size_t(levels - 1), '[') + std::string(std::size_t(levels - 1), ']') + "\n";
    };
    const auto block = [](int levels) {
        std::string text;
        for (int i = 0; i < levels; ++i) text += std::string(std::size_t(i), ' ') + "k:\n";
        return text;
    };
    CHECK_NOTHROW(yaml::parse(flow(yaml::kMaxDepth), kYamlSource));
    checkYamlRefused(flow(yaml::kMaxDepth + 1), 1, "nested deeper than 64 levels");
    CHECK_NOTHROW(yaml::parse(block(yaml::kMaxDepth), kYamlSource));
    checkYamlRefused(block(yaml::kMaxDepth + 1), yaml::kMaxDepth + 1, "nested deeper than 64 levels");
    std::string dashes;
    for (int i = 0; i < yaml::kMaxDepth; ++i) dashes += "- ";
    CHECK_NOTHROW(yaml::parse(dashes + "x\n", kYamlSource));
    checkYamlRefused(dashes + "- x\n", 1, "nested deeper than 64 levels");
    // Far deeper than the limit: refused at the limit, long before the call stack matters.
    checkYamlRefused(std::string(100000, '['), 1, "nested deeper than 64 levels");
}

TEST_CASE("OpenCV FileStorage XML reads as elements with their text and type_id", "[io]")
{
    const xml::Element root = xml::parse(kOpenCvXml, kXmlSource);
    CHECK(root.name == "opencv_storage");
    CHECK(root.line == 2);
    REQUIRE(root.children.size() == 6);
    CHECK(childOf(root, "image_width").text == "640");
    CHECK(childOf(root, "calibration_time").text == "\"Tue 04 Jul 2023 10:00:00 CEST\"");
    const xml::Element& cameraMatrix = childOf(root, "camera_matrix");
    CHECK(cameraMatrix.line == 6);
    REQUIRE(cameraMatrix.attribute("type_id") != nullptr);
    CHECK(*cameraMatrix.attribute("type_id") == "opencv-matrix");
    CHECK(cameraMatrix.attribute("type") == nullptr);
    CHECK(childOf(cameraMatrix, "rows").text == "3");
    CHECK(childOf(cameraMatrix, "dt").text == "d");
    CHECK(childOf(cameraMatrix, "data").text == "\n    657.46697810243404 0. 319.5 0. 657.46697810243404 239.5 0. 0. 1.");
    CHECK(childOf(cameraMatrix, "data").line == 10);
    CHECK(childOf(childOf(root, "distortion_coefficients"), "data").text ==
          "\n    -4.1802327018241026e-01 5.0715243805833121e-01 0. 0.\n    -5.7843596847939704e-01");
    CHECK(root.child("Camera_Matrix") == nullptr);
    CHECK(root.childIgnoringCase("Camera_Matrix") == &cameraMatrix);
}

TEST_CASE("XML entities, character references, CDATA and comments resolve as XML says", "[io]")
{
    const xml::Element root = xml::parse("\xEF\xBB\xBF<?xml version='1.0' encoding='utf-8'?>\r\n"
                                         "<!-- written by hand -->\r\n"
                                         "<root a='x &amp; &quot;y&quot;' b=\"line\nbreak\">\r\n"
                                         "  <t>&lt;&gt;&amp;&apos;&quot; &#955;&#x3bb;&#x1F600;</t>\r\n"
                                         "  <!-- between -->\r\n"
                                         "  <c><![CDATA[<not> &markup;]]></c>\r\n"
                                         "  <empty/><empty attr = \"1\" />\r\n"
                                         "</root>\r\n"
                                         "<!-- after -->\r\n",
                                         kXmlSource);
    CHECK(root.name == "root");
    CHECK(*root.attribute("a") == "x & \"y\"");
    CHECK(*root.attribute("b") == "line break");
    CHECK(childOf(root, "t").text == "<>&'\" \xCE\xBB\xCE\xBB\xF0\x9F\x98\x80");
    CHECK(childOf(root, "c").text == "<not> &markup;");
    CHECK(childOf(root, "c").line == 7);
    REQUIRE(root.children.size() == 4);
    CHECK(root.children[2].name == "empty");
    CHECK(root.children[3].attributes.size() == 1);
    CHECK(root.text == "\n  \n  \n  \n  \n");
}

TEST_CASE("Each XML refusal is an Error naming the source, the line and the rule", "[io]")
{
    checkXmlRefused("<?xml version=\"1.0\"?>\n<!DOCTYPE x [<!ENTITY a \"b\">]>\n<x>&a;</x>\n", 2, "DOCTYPE");
    checkXmlRefused("<x>\n&a;</x>\n", 2, "unknown entity '&a;'");
    checkXmlRefused("<x>\n<!DOCTYPE y></x>\n", 2, "DOCTYPE");
    checkXmlRefused("<x><?php echo 1; ?></x>\n", 1, "processing instructions");
    checkXmlRefused("<?xml-stylesheet href='a'?>\n<x/>\n", 1, "processing instructions");
    checkXmlRefused("\n<x/>\n<?xml version='1.0'?>\n", 3, "at the very start");
    checkXmlRefused("<a>\n<b></a>\n", 2, "</a> closes <b> opened at line 2");
    checkXmlRefused("<a>\n<b>\n", 2, "<b> opened here is never closed");
    checkXmlRefused("<a\n x='1'", 1, "start tag <a> opened here is not closed");
    checkXmlRefused("<a x='1'\n x='2'/>", 2, "attribute 'x' is repeated");
    checkXmlRefused("<a x='1'y='2'/>", 1, "separated");
    checkXmlRefused("<a x=1/>", 1, "must be quoted");
    checkXmlRefused("<a x='<'/>", 1, "'<' inside the value");
    checkXmlRefused("<a x='1/>\n", 1, "is not closed");
    checkXmlRefused("<a/>\n<b/>\n", 2, "an element after the root element <a>");
    checkXmlRefused("<a/>\ntext\n", 2, "text after the root element <a>");
    checkXmlRefused("text<a/>", 1, "text before the root element");
    checkXmlRefused("<!-- only -->\n", 2, "no root element");
    checkXmlRefused("<a>&#0;</a>", 1, "does not name an XML character");
    checkXmlRefused("<a>&#xD800;</a>", 1, "does not name an XML character");
    checkXmlRefused("<a>&#x110000;</a>", 1, "does not name an XML character");
    checkXmlRefused("<a>&#99999999999999999999;</a>", 1, "'&' must start an entity");
    checkXmlRefused("<a>&#xZZ;</a>", 1, "does not name an XML character");
    checkXmlRefused("<a>fish & chips</a>", 1, "'&' must start an entity");
    checkXmlRefused("<a>\n<![CDATA[ x </a>", 2, "CDATA section opened here is not closed");
    checkXmlRefused("<a>]]></a>", 1, "']]>' outside a CDATA section");
    checkXmlRefused("<a>\n<!-- a -- b --></a>", 2, "'--' inside a comment");
    checkXmlRefused("<a><!-- open</a>", 1, "comment opened here is not closed");
    checkXmlRefused("<?xml version='1.0' encoding='ISO-8859-1'?><a/>", 1, "UTF-8 only");
    checkXmlRefused("<a>\n< b/></a>", 2, "expected an element name");
    checkXmlRefused("<a>caf\xE9</a>", 1, "not valid UTF-8");
    checkXmlRefused("<a>\x0B</a>", 1, "control character 0x0B");

    std::string deep;
    for (int i = 0; i < xml::kMaxDepth; ++i) deep += "<e>";
    for (int i = 0; i < xml::kMaxDepth; ++i) deep += "</e>";
    CHECK_NOTHROW(xml::parse(deep, kXmlSource));
    checkXmlRefused("<f>" + deep + "</f>", 1, "nested deeper than 64 levels");
    // Far deeper than the limit: refused at the limit, without recursion.
    std::string deeper;
    for (int i = 0; i < 100000; ++i) deeper += "<e>";
    checkXmlRefused(deeper, 1, "nested deeper than 64 levels");
}
