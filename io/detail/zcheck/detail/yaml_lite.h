#pragma once
// A strict reader for the YAML that camera calibration files are written in (target
// zcheck_io_detail, never installed): OpenCV FileStorage (`%YAML:1.0`, `!!opencv-matrix`, flow lists wrapped over
// lines), ROS camera_calibration_parsers files and `rostopic echo` / `ros2 topic echo`
// CameraInfo messages. Not a general YAML parser, and not meant to become one.
//
// Read: an optional UTF-8 BOM; `%YAML 1.x` or OpenCV's non-standard `%YAML:1.0`, then an
// optional `---`; the first document only, which ends at a second `---`, at `...` or at the
// end of the text; `#` comments; block maps and sequences by indentation (a sequence may sit
// at its key's indentation, as PyYAML writes `d:\n- 0.0`); flow `[..]` and `{..}`, nested
// and over several lines; a tag before a value (`!!opencv-matrix`); plain, '..' and ".."
// scalars on one line. In a flow map a plain key ends at its first ':', so OpenCV's
// `{ x:167 }` reads as x = 167.
//
// Refused, with "<source>: line N: <rule>": anchors and aliases, block (`|`, `>`) and
// multi-line scalars, explicit keys (`? `), tabs used for indentation, a key repeated in one
// map, unterminated quotes or flow collections, inconsistent indentation, nesting deeper
// than 64 collections, a top level that is not a map or sequence, other directives (%TAG),
// text that is not UTF-8, control characters (no size limit: the file's format sets it). Scalars are kept as
// text: "1.", "6.57e+002", ".Inf", "null" and "True" are the caller's to interpret.
#include <cstddef>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace zcheck::yaml {

struct Node {
    enum class Kind { Scalar, Sequence, Map };
    Kind kind = Kind::Scalar;
    std::string scalar;   // Scalar: its text, quotes removed and escapes resolved; "" for an empty value
    bool quoted = false;  // the scalar was quoted ('..' or "..")
    std::string tag;      // a tag as written without its leading '!' or "!!" ("opencv-matrix"), "" if none
    int line = 0;         // 1-based line where the node starts (its tag, if it has one)
    std::vector<Node> items;                            // Sequence
    std::vector<std::pair<std::string, Node>> entries;  // Map, in file order; keys are unique
    const Node* find(const std::string& key) const;             // exact key, nullptr if absent
    const Node* findIgnoringCase(const std::string& key) const; // ASCII case-insensitive; the first match
};

// The deepest nesting of collections accepted (the top-level map or sequence is 1).
inline constexpr int kMaxDepth = 64;

// Parses the first document of `text`, whose top level must be a map or a sequence.
// Throws zcheck::Error("<source>: line N: <what is wrong>").
Node parse(std::string_view text, const std::string& source);

}  // namespace zcheck::yaml
