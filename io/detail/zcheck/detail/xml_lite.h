#pragma once
// A strict reader for the XML that OpenCV FileStorage writes (target zcheck_io_detail, never installed):
//   <?xml version="1.0"?>
//   <opencv_storage>
//   <camera_matrix type_id="opencv-matrix">
//     <rows>3</rows><cols>3</cols><dt>d</dt>
//     <data>
//       657.46 0. 319.5 0. 657.46 239.5 0. 0. 1.</data></camera_matrix>
//   </opencv_storage>
// Not a general XML parser, and not meant to become one.
//
// Read: an optional UTF-8 BOM; an `<?xml ...?>` declaration at the start (encoding UTF-8 or
// US-ASCII, if named); comments anywhere between elements; elements with '..' or ".."
// attributes; `<a/>`; character data with the five predefined entities (&lt; &gt; &amp;
// &quot; &apos;) and character references (&#N; &#xN;, XML characters only, stored as UTF-8);
// CDATA sections. Line breaks are read as "\n" (CRLF and CR too, as XML says), and tabs and
// line breaks inside attribute values as spaces.
//
// Refused, with "<source>: line N: <rule>": DOCTYPE and any DTD (so no entity is ever
// expanded), processing instructions other than the declaration, mismatched or unclosed
// tags, a repeated attribute, text or elements after the root element, nesting deeper than
// 64 elements, "--" inside a comment, "]]>" outside CDATA, text that is not UTF-8, control
// characters. The parser does not recurse; the text is as long as its file may be (the
// format's limit, camera_formats.h).
#include <cstddef>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace zcheck::xml {

struct Element {
    std::string name;
    std::vector<std::pair<std::string, std::string>> attributes;  // in file order; names are unique
    std::string text;               // the character data directly inside, entities resolved, concatenated
    std::vector<Element> children;
    int line = 0;                   // 1-based line of the start tag's '<'
    const Element* child(const std::string& name) const;              // first child of that name
    const Element* childIgnoringCase(const std::string& name) const;  // ASCII case-insensitive
    const std::string* attribute(const std::string& name) const;      // nullptr if absent
};

// The deepest nesting of elements accepted (the root element is 1).
inline constexpr int kMaxDepth = 64;

// Parses `text` and returns its root element. Throws zcheck::Error("<source>: line N: ...").
Element parse(std::string_view text, const std::string& source);

}  // namespace zcheck::xml
