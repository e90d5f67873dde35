#pragma once
// What the YAML and XML subset readers (yaml_lite.h, xml_lite.h) share: their text checked and
// normalised before they parse, and UTF-8 in and out. Private to zcheck (target zcheck_io_detail).
#include <cstdint>
#include <string>
#include <string_view>

namespace zcheck::text {

// Length of the well-formed UTF-8 sequence at text[i] (no overlong forms, no surrogates,
// nothing above U+10FFFF), 0 if there is none.
std::size_t utf8Length(std::string_view text, std::size_t i);
// Appends code point `cp` (≤ U+10FFFF) as UTF-8.
void appendUtf8(std::string& out, std::uint32_t cp);
// ASCII case folding, for keys and names that files write in either case.
char lowerAscii(char c);
bool equalIgnoringCase(std::string_view a, std::string_view b);
// `text` quoted for a message: '...', at most 40 characters shown (printableExcerpt), "..." when cut.
std::string quoted(std::string_view text);
// Throws Error("<source>: line <line>: <what>").
[[noreturn]] void failAt(const std::string& source, int line, const std::string& what);
// The text without its BOM, CRLF and lone CR read as LF (files written on Windows), after
// checking that it is UTF-8 (UTF-16 is named) and free of control characters but tabs and line
// breaks. Parsers then deal with '\n' alone and may use '\0' as the end. No size limit here:
// the file was read within its format's (camera_formats.h, input_file.h).
std::string normalizedText(std::string_view text, const std::string& source);

}  // namespace zcheck::text
