#include "zcheck/detail/yaml_lite.h"

#include "zcheck/detail/text_checks.h"
#include "zcheck/error.h"

#include <cstdint>
#include <cstdio>
#include <unordered_map>

namespace zcheck::yaml {

namespace {

// The text is checked first (normalizedText) to hold no NUL, so '\0' can stand for its end.
bool isBlank(char c) { return c == ' ' || c == '\t'; }
bool isBlankOrEnd(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\0'; }
bool isFlowIndicator(char c) { return c == ',' || c == '[' || c == ']' || c == '{' || c == '}'; }
bool isHexDigit(char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F'); }
bool isAlnum(char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); }
// Tags are names like "opencv-matrix" or "str"; URI escapes and punctuation beyond these are
// not needed by any writer we read.
bool isTagChar(char c) { return isAlnum(c) || c == '-' || c == '_' || c == '.' || c == ':' || c == '/' || c == '~'; }
using text::equalIgnoringCase;
using text::lowerAscii;
using text::quoted;

// Where a node sits in block context, which decides what may start there.
struct Place {
    int parentIndent;  // a node on the lines below must be indented more than this (-1 at the top)
    bool mapValue;     // the value of a block map key: a sequence may sit at the key's indentation
    bool afterKey;     // on the line of its key or tag: no block collection may start here
    bool tagged;       // a tag was read already: a second one is an error, which also bounds recursion
};

class Parser {
public:
    Parser(std::string_view text, const std::string& source) : text_(zcheck::text::normalizedText(text, source)), source_(source) {}

    Node parseDocument();

private:
    std::string text_;
    const std::string& source_;
    std::size_t pos_ = 0;
    std::size_t lineStart_ = 0;
    int line_ = 1;

    char charAt(std::size_t i) const { return i < text_.size() ? text_[i] : '\0'; }
    char peek(std::size_t ahead = 0) const { return charAt(pos_ + ahead); }
    int column() const { return int(pos_ - lineStart_); }
    void newline()  // at a '\n'
    {
        ++pos_;
        ++line_;
        lineStart_ = pos_;
    }
    [[noreturn]] void fail(int line, const std::string& what) const { zcheck::text::failAt(source_, line, what); }
    // The text from `start` to the end of its line, quoted for a message.
    std::string lineFrom(std::size_t start) const
    {
        std::size_t end = start;
        while (charAt(end) != '\n' && charAt(end) != '\0') ++end;
        return quoted(std::string_view(text_).substr(start, end - start));
    }
    std::string restOfLine() const { return lineFrom(pos_); }

    void skipInlineSpace()
    {
        while (isBlank(peek())) ++pos_;
    }
    bool atLineEnd() const { return peek() == '\n' || peek() == '\0' || peek() == '#'; }
    void finishLine();
    void skipBlankLines();
    bool atMarker(const char* marker) const;
    int lineIndent() const;
    int nextContentLine();
    bool sequenceItemAt(std::size_t i) const { return charAt(i) == '-' && isBlankOrEnd(charAt(i + 1)); }
    void checkDepth(int depth) const
    {
        if (depth > kMaxDepth) fail(line_, "nested deeper than " + std::to_string(kMaxDepth) + " levels");
    }

    void parseDirective(bool& sawYaml);
    Node parseBlockNode(const Place& place, int depth);
    Node parseNodeBelow(const Place& place, int depth, int emptyLine);
    Node parseBlockMap(int column, int depth);
    Node parseBlockSequence(int column, bool atParentIndent, int depth);
    std::string parseBlockKey(int mapLine);
    bool keyAhead();
    std::size_t plainKeyEnd() const;
    Node parseInlineValue(int depth);

    void skipFlowSpace(int openLine, const char* what);
    Node parseFlowNode(int depth, int openLine, const char* what);
    Node parseFlowValue(int depth);
    Node parseFlowSequence(int depth);
    Node parseFlowMap(int depth);
    std::string scanFlowPlain(bool stopAtColon);

    void refuseIndicator(bool flow) const;
    std::string scanTag(bool flow);
    std::string scanQuoted();
    void readEscape(std::string& out, int line);
};

// After a value: blanks, a comment, then the end of the line.
void Parser::finishLine()
{
    skipInlineSpace();
    if (peek() == '#') {
        // YAML reads '#' as a comment only after whitespace: "a#b" is one value.
        if (pos_ > lineStart_ && !isBlank(text_[pos_ - 1]))
            fail(line_, "unexpected text after the value: " + restOfLine() + " (a comment needs a space before '#')");
        while (peek() != '\n' && peek() != '\0') ++pos_;
    }
    if (peek() == '\n') {
        newline();
    } else if (peek() != '\0') {
        fail(line_, "unexpected text after the value: " + restOfLine());
    }
}

// From a line start, past blank and comment-only lines: to the start of a line with content,
// or to the end.
void Parser::skipBlankLines()
{
    for (;;) {
        std::size_t i = pos_;
        while (isBlank(charAt(i))) ++i;
        if (charAt(i) == '#')
            while (charAt(i) != '\n' && charAt(i) != '\0') ++i;
        if (charAt(i) == '\0') {
            pos_ = text_.size();
            return;
        }
        if (charAt(i) != '\n') return;
        pos_ = i;
        newline();
    }
}

bool Parser::atMarker(const char* marker) const
{
    return pos_ == lineStart_ && text_.compare(pos_, 3, marker) == 0 && isBlankOrEnd(charAt(pos_ + 3));
}

// The indentation of the content line starting at pos_. YAML indents with spaces only: a tab
// there would be read as one column by some readers and as eight by people.
int Parser::lineIndent() const
{
    std::size_t i = pos_;
    while (charAt(i) == ' ') ++i;
    if (charAt(i) == '\t') fail(line_, "a tab in the indentation (YAML indents with spaces only)");
    return int(i - pos_);
}

// The indentation of the next line with content, pos_ left at that line's start; -1 at the end
// of the text or of the document ("---" or "..." at the start of a line).
int Parser::nextContentLine()
{
    skipBlankLines();
    if (peek() == '\0' || atMarker("---") || atMarker("...")) return -1;
    return lineIndent();
}

Node Parser::parseDocument()
{
    skipBlankLines();
    bool sawYaml = false;
    while (peek() == '%') {
        parseDirective(sawYaml);
        skipBlankLines();
    }
    // OpenCV's older files have "%YAML:1.0" and no "---": both forms are read.
    if (atMarker("---")) {
        pos_ += 3;
        skipInlineSpace();
        if (!atLineEnd()) fail(line_, "a value on the '---' line is not supported; start the document on the next line");
        finishLine();
    }
    const int indent = nextContentLine();
    if (indent < 0) fail(line_, "the document is empty (a map or a sequence was expected)");
    pos_ += std::size_t(indent);
    Node root = parseBlockNode(Place{-1, false, false, false}, 0);
    if (root.kind == Node::Kind::Scalar)
        fail(root.line, "the document must be a map or a sequence, not a single value");
    if (nextContentLine() >= 0)
        fail(line_, "this line is indented less than the line where the document starts (line " + std::to_string(root.line) + ")");
    // Whatever follows the document's end ("---", "..."), such as the next message of
    // `ros2 topic echo`, is not read.
    return root;
}

void Parser::parseDirective(bool& sawYaml)
{
    const int line = line_;
    if (text_.compare(pos_, 5, "%YAML") != 0 || !(peek(5) == ' ' || peek(5) == '\t' || peek(5) == ':'))
        fail(line, "the directive " + restOfLine() + " is not supported (only %YAML)");
    if (sawYaml) fail(line, "a second %YAML directive");
    sawYaml = true;
    pos_ += 6;  // "%YAML" and the separator: OpenCV writes "%YAML:1.0", the standard "%YAML 1.2"
    skipInlineSpace();
    const std::size_t start = pos_;
    while ((peek() >= '0' && peek() <= '9') || peek() == '.') ++pos_;
    const std::string version = text_.substr(start, pos_ - start);
    if (version.size() < 3 || version.compare(0, 2, "1.") != 0 || version.find('.', 2) != std::string::npos)
        fail(line, "YAML version " + quoted(version) + " is not supported (1.x only)");
    finishLine();
}

// A node in block context at pos_ (its first character, not a blank).
Node Parser::parseBlockNode(const Place& place, int depth)
{
    const char c = peek();
    if (c == '-' && isBlankOrEnd(peek(1))) {
        if (place.afterKey) fail(line_, "a '- ' sequence cannot start on the line of a key or tag; put its items on the lines below");
        return parseBlockSequence(column(), false, depth + 1);
    }
    if (c == '!') {
        if (place.tagged) fail(line_, "a second tag on one value");
        const int line = line_;
        std::string tag = scanTag(false);
        skipInlineSpace();
        Node node;
        if (atLineEnd()) {
            // "camera_matrix: !!opencv-matrix" with the map on the lines below.
            finishLine();
            node = parseNodeBelow(Place{place.parentIndent, place.mapValue, false, true}, depth, line);
        } else {
            node = parseBlockNode(Place{place.parentIndent, place.mapValue, true, true}, depth);
        }
        node.tag = std::move(tag);
        node.line = line;
        return node;
    }
    if (c == '?' && isBlankOrEnd(peek(1))) fail(line_, "explicit keys ('? ') are not supported");
    if (keyAhead()) {
        if (place.afterKey) fail(line_, "a map cannot start on the line of a key or tag ('a: b: c'); quote the value or put the map on the lines below");
        return parseBlockMap(column(), depth + 1);
    }
    Node node = parseInlineValue(depth);
    finishLine();
    return node;
}

// The value on the lines below a key, a '-' or a tag that ends its line: a node indented more
// than the parent, a sequence at a map key's own indentation, or else nothing (an empty value).
Node Parser::parseNodeBelow(const Place& place, int depth, int emptyLine)
{
    const int indent = nextContentLine();
    if (indent > place.parentIndent) {
        pos_ += std::size_t(indent);
        return parseBlockNode(Place{place.parentIndent, place.mapValue, false, place.tagged}, depth);
    }
    if (indent >= 0 && indent == place.parentIndent && place.mapValue && sequenceItemAt(pos_ + std::size_t(indent))) {
        pos_ += std::size_t(indent);
        return parseBlockSequence(indent, true, depth + 1);
    }
    Node empty;
    empty.line = emptyLine;
    return empty;
}

Node Parser::parseBlockMap(int column, int depth)
{
    checkDepth(depth);
    Node map;
    map.kind = Node::Kind::Map;
    map.line = line_;
    std::unordered_map<std::string, int> keyLines;
    for (;;) {
        const int keyLine = line_;
        if (sequenceItemAt(pos_))
            fail(line_, "a '- ' item where a key of the map at line " + std::to_string(map.line) + " was expected");
        std::string key = parseBlockKey(map.line);
        // A repeated key is refused: readers that keep the last one silently hide a mistake.
        const auto [first, isNew] = keyLines.emplace(key, keyLine);
        if (!isNew) fail(keyLine, "the key " + quoted(key) + " is repeated (first at line " + std::to_string(first->second) + ")");
        skipInlineSpace();
        Node value;
        if (atLineEnd()) {
            finishLine();
            value = parseNodeBelow(Place{column, true, false, false}, depth, keyLine);
        } else {
            value = parseBlockNode(Place{column, true, true, false}, depth);
        }
        map.entries.emplace_back(std::move(key), std::move(value));
        const int indent = nextContentLine();
        if (indent < column) return map;
        if (indent > column)
            fail(line_, "this line is indented more than the keys of the map at line " + std::to_string(map.line) +
                            " (a value continued on a second line, or inconsistent indentation)");
        pos_ += std::size_t(indent);
    }
}

// `atParentIndent`: the value of a map key written at the key's own indentation (PyYAML's
// "d:\n- 0.0"); a line there that is not an item ends the sequence and the map goes on.
Node Parser::parseBlockSequence(int column, bool atParentIndent, int depth)
{
    checkDepth(depth);
    Node sequence;
    sequence.kind = Node::Kind::Sequence;
    sequence.line = line_;
    for (;;) {
        const int itemLine = line_;
        ++pos_;  // '-'
        const std::size_t afterDash = pos_;
        skipInlineSpace();
        if (atLineEnd()) {
            finishLine();
            sequence.items.push_back(parseNodeBelow(Place{column, false, false, false}, depth, itemLine));
        } else {
            // The content after "- " is indented by the dash and the blanks: tabs cannot count.
            for (std::size_t i = afterDash; i < pos_; ++i)
                if (text_[i] == '\t') fail(line_, "a tab after '-' indents the item (YAML indents with spaces only)");
            sequence.items.push_back(parseBlockNode(Place{column, false, false, false}, depth));
        }
        const int indent = nextContentLine();
        if (indent < column) return sequence;
        if (indent > column)
            fail(line_, "this line is indented more than the '- ' items of the sequence at line " + std::to_string(sequence.line) +
                            " (a value continued on a second line, or inconsistent indentation)");
        if (!sequenceItemAt(pos_ + std::size_t(indent))) {
            if (atParentIndent) return sequence;
            fail(line_, "expected a '- ' item of the sequence at line " + std::to_string(sequence.line) + ", found " +
                            lineFrom(pos_ + std::size_t(indent)));
        }
        pos_ += std::size_t(indent);
    }
}

// A block map's key and its ':'; pos_ is left after the ':'.
std::string Parser::parseBlockKey(int mapLine)
{
    std::string key;
    if (peek() == '"' || peek() == '\'') {
        key = scanQuoted();
        skipInlineSpace();
    } else {
        if (peek() == '[' || peek() == '{') fail(line_, "a flow collection as a key is not supported");
        if (peek() == '!') fail(line_, "a tag on a key is not supported");
        refuseIndicator(false);
        const std::size_t colon = plainKeyEnd();
        if (colon == std::string::npos)
            fail(line_, "expected a key ('name: value') of the map at line " + std::to_string(mapLine) + ", found " + restOfLine());
        std::size_t end = colon;
        while (end > pos_ && isBlank(text_[end - 1])) --end;
        key = text_.substr(pos_, end - pos_);
        pos_ = colon;
    }
    if (peek() != ':' || !isBlankOrEnd(peek(1))) fail(line_, "expected ': ' after the key " + quoted(key));
    ++pos_;
    return key;
}

// Whether the block node at pos_ is a map: a key followed by ': ' (or ':' at the line's end).
bool Parser::keyAhead()
{
    const char c = peek();
    if (c == '"' || c == '\'') {
        const std::size_t start = pos_;  // a quoted value ends on its line: line_ is unchanged
        scanQuoted();
        skipInlineSpace();
        const bool key = peek() == ':' && isBlankOrEnd(peek(1));
        pos_ = start;
        return key;
    }
    if (c == '[' || c == '{') return false;
    return plainKeyEnd() != std::string::npos;
}

// The ':' ending a plain key at pos_ (the first ':' followed by a blank or the line's end,
// before any comment), or npos.
std::size_t Parser::plainKeyEnd() const
{
    for (std::size_t i = pos_; charAt(i) != '\n' && charAt(i) != '\0'; ++i) {
        if (text_[i] == '#' && i > pos_ && isBlank(text_[i - 1])) return std::string::npos;
        if (text_[i] == ':' && isBlankOrEnd(charAt(i + 1))) return i;
    }
    return std::string::npos;
}

// A value on the line of its key, '-' or tag: a flow collection, a quoted scalar or a plain
// scalar running to the end of the line (trailing blanks and comment removed).
Node Parser::parseInlineValue(int depth)
{
    const char c = peek();
    if (c == '[' || c == '{' || c == '"' || c == '\'') return parseFlowValue(depth);
    refuseIndicator(false);
    Node node;
    node.line = line_;
    const std::size_t start = pos_;
    std::size_t end = pos_;
    while (peek() != '\n' && peek() != '\0') {
        const char here = peek();
        if (here == '#' && pos_ > start && isBlank(text_[pos_ - 1])) break;
        if (here == ':' && isBlankOrEnd(peek(1)))
            fail(line_, "a ': ' inside the value " + quoted(std::string_view(text_).substr(start, pos_ + 1 - start)) +
                            " (a map cannot start on the line of a key); quote the value");
        ++pos_;
        if (!isBlank(here)) end = pos_;
    }
    node.scalar = text_.substr(start, end - start);
    return node;
}

// Blanks, line breaks and comments inside a flow collection. The text may end, or a new
// document start, only once the collection is closed.
void Parser::skipFlowSpace(int openLine, const char* what)
{
    for (;;) {
        const char c = peek();
        if (isBlank(c)) {
            ++pos_;
        } else if (c == '#' && (pos_ == lineStart_ || isBlank(text_[pos_ - 1]))) {
            while (peek() != '\n' && peek() != '\0') ++pos_;
        } else if (c == '\n') {
            newline();
            if (atMarker("---") || atMarker("..."))
                fail(line_, std::string("a document marker inside the flow ") + what + " opened at line " + std::to_string(openLine) +
                                " (it is not closed)");
        } else if (c == '\0') {
            fail(openLine, std::string("the flow ") + what + " opened here is not closed");
        } else {
            return;
        }
    }
}

// A node inside a flow collection at pos_: an optional tag, then a value.
Node Parser::parseFlowNode(int depth, int openLine, const char* what)
{
    if (peek() != '!') return parseFlowValue(depth);
    const int line = line_;
    std::string tag = scanTag(true);
    skipFlowSpace(openLine, what);
    if (peek() == '!') fail(line_, "a second tag on one value");
    Node node;
    if (peek() != ',' && peek() != ']' && peek() != '}') node = parseFlowValue(depth);
    node.tag = std::move(tag);
    node.line = line;
    return node;
}

Node Parser::parseFlowValue(int depth)
{
    const char c = peek();
    if (c == '[') return parseFlowSequence(depth + 1);
    if (c == '{') return parseFlowMap(depth + 1);
    Node node;
    node.line = line_;
    if (c == '"' || c == '\'') {
        node.scalar = scanQuoted();
        node.quoted = true;
        return node;
    }
    refuseIndicator(true);
    node.scalar = scanFlowPlain(false);
    return node;
}

Node Parser::parseFlowSequence(int depth)
{
    checkDepth(depth);
    Node sequence;
    sequence.kind = Node::Kind::Sequence;
    sequence.line = line_;
    const std::string opened = " in the flow sequence opened at line " + std::to_string(line_);
    ++pos_;  // '['
    for (;;) {
        skipFlowSpace(sequence.line, "sequence");
        if (peek() == ']') break;
        if (peek() == ',') fail(line_, "an empty entry" + opened);
        sequence.items.push_back(parseFlowNode(depth, sequence.line, "sequence"));
        skipFlowSpace(sequence.line, "sequence");
        if (peek() == ',') {
            ++pos_;
            continue;
        }
        if (peek() == ']') break;
        if (peek() == ':')
            fail(line_, "a key inside a flow sequence ('[a: b]') is not supported" + opened +
                            " (is a ']' missing there?)");
        fail(line_, "expected ',' or ']'" + opened + ", found " + restOfLine() + " (a value cannot continue on another line)");
    }
    ++pos_;  // ']'
    return sequence;
}

Node Parser::parseFlowMap(int depth)
{
    checkDepth(depth);
    Node map;
    map.kind = Node::Kind::Map;
    map.line = line_;
    const std::string opened = " in the flow map opened at line " + std::to_string(line_);
    std::unordered_map<std::string, int> keyLines;
    ++pos_;  // '{'
    for (;;) {
        skipFlowSpace(map.line, "map");
        if (peek() == '}') break;
        if (peek() == ',') fail(line_, "an empty entry" + opened);
        const int keyLine = line_;
        std::string key;
        if (peek() == '"' || peek() == '\'') {
            key = scanQuoted();
        } else {
            if (peek() == '[' || peek() == '{') fail(line_, "a flow collection as a key is not supported");
            if (peek() == '!') fail(line_, "a tag on a key is not supported");
            refuseIndicator(true);
            // A plain key ends at its first ':', as OpenCV means "{ x:167 }" (YAML 1.2 would
            // read one scalar "x:167"); a key holding ':' must be quoted.
            key = scanFlowPlain(true);
            if (key.empty()) fail(line_, "an empty key" + opened);
        }
        const auto [first, isNew] = keyLines.emplace(key, keyLine);
        if (!isNew) fail(keyLine, "the key " + quoted(key) + " is repeated (first at line " + std::to_string(first->second) + ")");
        skipFlowSpace(map.line, "map");
        Node value;
        value.line = line_;
        if (peek() == ':') {
            ++pos_;
            skipFlowSpace(map.line, "map");
            if (peek() != ',' && peek() != '}') value = parseFlowNode(depth, map.line, "map");
        }  // else a key alone, "{a, b}": an empty value, as YAML reads it
        map.entries.emplace_back(std::move(key), std::move(value));
        skipFlowSpace(map.line, "map");
        if (peek() == ',') {
            ++pos_;
            continue;
        }
        if (peek() == '}') break;
        fail(line_, "expected ',' or '}'" + opened + ", found " + restOfLine() + " (a value cannot continue on another line)");
    }
    ++pos_;  // '}'
    return map;
}

// A plain scalar inside a flow collection: up to a flow indicator, ': ', a comment or the end
// of the line, trailing blanks removed.
std::string Parser::scanFlowPlain(bool stopAtColon)
{
    const std::size_t start = pos_;
    std::size_t end = pos_;
    for (;;) {
        const char c = peek();
        if (c == '\n' || c == '\0' || isFlowIndicator(c)) break;
        if (c == ':' && (stopAtColon || isBlankOrEnd(peek(1)) || isFlowIndicator(peek(1)))) break;
        if (c == '#' && pos_ > start && isBlank(text_[pos_ - 1])) break;
        ++pos_;
        if (!isBlank(c)) end = pos_;
    }
    return text_.substr(start, end - start);
}

// Characters that cannot start a plain scalar, each refused with the YAML feature it means.
void Parser::refuseIndicator(bool flow) const
{
    const char c = peek();
    const char next = peek(1);
    const bool separated = isBlankOrEnd(next) || (flow && isFlowIndicator(next));
    switch (c) {
    case '&':
    case '*': fail(line_, "anchors and aliases ('&', '*') are not supported");
    case '|':
    case '>': fail(line_, "block scalars ('|', '>') are not supported; write the value on one line");
    case '!': fail(line_, "a tag is not allowed here");
    case '#': fail(line_, "unexpected '#' (a comment needs a space before it)");
    case ',':
    case '[':
    case ']':
    case '{':
    case '}': fail(line_, std::string("unexpected '") + c + "'");
    case '%':
    case '@':
    case '`': fail(line_, std::string("'") + c + "' cannot start a plain value (it is reserved); quote the value");
    case '-':
        if (separated) fail(line_, flow ? "a '- ' item inside a flow collection" : "unexpected '- '");
        break;
    case '?':
        if (separated) fail(line_, "explicit keys ('? ') are not supported");
        break;
    case ':':
        if (separated) fail(line_, "a ':' without a key");
        break;
    default: break;
    }
}

// A tag at pos_ ('!'): "!!opencv-matrix" gives "opencv-matrix", "!local" gives "local".
std::string Parser::scanTag(bool flow)
{
    const int line = line_;
    ++pos_;
    if (peek() == '!') {
        ++pos_;
    } else if (peek() == '<') {
        fail(line, "verbatim tags ('!<...>') are not supported");
    }
    const std::size_t start = pos_;
    while (isTagChar(peek())) ++pos_;
    if (pos_ == start) fail(line, "an empty tag");
    if (peek() == '!') fail(line, "named tag handles ('!name!...') are not supported");
    if (!isBlankOrEnd(peek()) && !(flow && isFlowIndicator(peek())))
        fail(line, "the tag " + quoted(text_.substr(start, pos_ - start)) + " must be followed by a space, found " + restOfLine());
    return text_.substr(start, pos_ - start);
}

// A '..' or ".." scalar at pos_, which must end on its line (multi-line scalars are refused).
std::string Parser::scanQuoted()
{
    const char quote = peek();
    const int line = line_;
    ++pos_;
    std::string out;
    for (;;) {
        const char c = peek();
        if (c == '\n' || c == '\0')
            fail(line, std::string("unterminated ") + (quote == '"' ? "double" : "single") +
                           "-quoted value (a quoted value must end on the line where it starts)");
        ++pos_;
        if (c == quote) {
            if (quote == '\'' && peek() == '\'') {  // '' is a quote inside '..'
                out += '\'';
                ++pos_;
                continue;
            }
            return out;
        }
        if (c == '\\' && quote == '"') {
            readEscape(out, line);
            continue;
        }
        out += c;
    }
}

// The escape after a backslash in "..": YAML 1.2's set, less the escaped line break (a
// multi-line value) and NUL (which would cut the value short for any C string reader), plus
// \' because OpenCV's writer escapes a single quote that way inside "..".
void Parser::readEscape(std::string& out, int line)
{
    const char e = peek();
    if (e == '\n' || e == '\0')
        fail(line, "unterminated double-quoted value (a quoted value must end on the line where it starts)");
    ++pos_;
    int digits = 0;
    switch (e) {
    case '\\':
    case '"':
    case '\'':
    case '/':
    case ' ': out += e; return;
    case '\t':
    case 't': out += '\t'; return;
    case 'n': out += '\n'; return;
    case 'r': out += '\r'; return;
    case 'b': out += '\b'; return;
    case 'f': out += '\f'; return;
    case 'a': out += '\a'; return;
    case 'v': out += '\v'; return;
    case 'e': out += '\x1B'; return;
    case 'N': zcheck::text::appendUtf8(out, 0x85); return;
    case '_': zcheck::text::appendUtf8(out, 0xA0); return;
    case 'L': zcheck::text::appendUtf8(out, 0x2028); return;
    case 'P': zcheck::text::appendUtf8(out, 0x2029); return;
    case '0': fail(line_, "the escape '\\0' (a NUL inside a value) is not allowed");
    case 'x': digits = 2; break;
    case 'u': digits = 4; break;
    case 'U': digits = 8; break;
    default: fail(line_, "unknown escape " + quoted(std::string("\\") + e) + " in a double-quoted value");
    }
    std::uint32_t codePoint = 0;
    for (int i = 0; i < digits; ++i) {
        const char h = peek();
        if (!isHexDigit(h)) fail(line_, std::string("the escape '\\") + e + "' needs " + std::to_string(digits) + " hex digits");
        codePoint = codePoint * 16 + std::uint32_t(h <= '9' ? h - '0' : lowerAscii(h) - 'a' + 10);
        ++pos_;
    }
    if (codePoint == 0) fail(line_, "the escape for U+0000 (a NUL inside a value) is not allowed");
    if ((codePoint >= 0xD800 && codePoint <= 0xDFFF) || codePoint > 0x10FFFF)
        fail(line_, "an escape for a code point that is not a character (a surrogate or above U+10FFFF)");
    zcheck::text::appendUtf8(out, codePoint);
}

}  // namespace

const Node* Node::find(const std::string& key) const
{
    for (const auto& [name, value] : entries)
        if (name == key) return &value;
    return nullptr;
}

const Node* Node::findIgnoringCase(const std::string& key) const
{
    for (const auto& [name, value] : entries)
        if (equalIgnoringCase(name, key)) return &value;
    return nullptr;
}

Node parse(std::string_view text, const std::string& source)
{
    return Parser(text, source).parseDocument();
}

}  // namespace zcheck::yaml
