#include "zcheck/detail/xml_lite.h"

#include "zcheck/detail/text_checks.h"
#include "zcheck/error.h"

#include <cstdint>
#include <cstdio>
#include <unordered_set>

namespace zcheck::xml {

namespace {

// The text is checked first (normalizedText) to hold no NUL, so '\0' can stand for its end.
bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\n'; }
bool isDigit(char c) { return c >= '0' && c <= '9'; }
bool isLetter(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); }
// XML names: ASCII letters, '_' and ':' first, then digits, '-' and '.' too; any non-ASCII
// byte is let through as part of a (UTF-8, already validated) name character.
bool isNameStart(char c) { return isLetter(c) || c == '_' || c == ':' || static_cast<unsigned char>(c) >= 0x80; }
bool isNameChar(char c) { return isNameStart(c) || isDigit(c) || c == '-' || c == '.'; }
using text::equalIgnoringCase;
using text::lowerAscii;
using text::quoted;

// "<name>" for a message, readable whatever the name holds.
std::string tag(std::string_view name, const char* open = "<") { return open + printableExcerpt(name, 40) + ">"; }

// XML 1.0's Char production: what a character reference may name.
bool isXmlChar(std::uint32_t cp)
{
    return cp == 0x9 || cp == 0xA || cp == 0xD || (cp >= 0x20 && cp <= 0xD7FF) || (cp >= 0xE000 && cp <= 0xFFFD) ||
           (cp >= 0x10000 && cp <= 0x10FFFF);
}

class Parser {
public:
    Parser(std::string_view text, const std::string& source) : text_(zcheck::text::normalizedText(text, source)), source_(source) {}

    Element parseDocument();

private:
    std::string text_;
    const std::string& source_;
    std::size_t pos_ = 0;
    int line_ = 1;

    char charAt(std::size_t i) const { return i < text_.size() ? text_[i] : '\0'; }
    char peek(std::size_t ahead = 0) const { return charAt(pos_ + ahead); }
    bool lookingAt(std::string_view s) const { return text_.compare(pos_, s.size(), s) == 0; }
    // Moves on by one character, counting lines.
    void step()
    {
        if (text_[pos_] == '\n') ++line_;
        ++pos_;
    }
    bool skipSpace()
    {
        const std::size_t start = pos_;
        while (isSpace(peek())) step();
        return pos_ != start;
    }
    [[noreturn]] void fail(int line, const std::string& what) const { zcheck::text::failAt(source_, line, what); }
    std::string here() const
    {
        std::size_t end = pos_;
        while (charAt(end) != '\n' && charAt(end) != '\0') ++end;
        return quoted(std::string_view(text_).substr(pos_, end - pos_));
    }

    void parseDeclaration();
    void skipMisc(const char* where);
    void skipComment();
    std::string_view scanName();
    bool parseStartTag(Element& element);
    bool parseAttributes(Element& element, bool declaration);
    void parseEndTag(const Element& open);
    void readReference(std::string& out);
};

Element Parser::parseDocument()
{
    if (lookingAt("<?xml") && isSpace(peek(5))) parseDeclaration();
    skipMisc("before");
    if (peek() == '\0') fail(line_, "no root element");
    if (peek() != '<') fail(line_, "text before the root element: " + here());

    // Elements are built on an explicit stack, so hostile nesting cannot exhaust the call stack.
    std::vector<Element> open(1);
    Element root;
    if (parseStartTag(open.back())) {
        root = std::move(open.back());
        open.clear();
    }
    while (!open.empty()) {
        Element& current = open.back();
        const char c = peek();
        if (c == '\0') fail(current.line, "the element " + tag(current.name) + " opened here is never closed");
        if (c == '&') {
            readReference(current.text);
        } else if (c != '<') {
            if (lookingAt("]]>")) fail(line_, "']]>' outside a CDATA section");
            current.text += c;
            step();
        } else if (lookingAt("</")) {
            parseEndTag(current);
            Element done = std::move(current);
            open.pop_back();
            if (open.empty()) {
                root = std::move(done);
            } else {
                open.back().children.push_back(std::move(done));
            }
        } else if (lookingAt("<!--")) {
            skipComment();
        } else if (lookingAt("<![CDATA[")) {
            const int line = line_;
            const std::size_t end = text_.find("]]>", pos_ + 9);
            if (end == std::string::npos) fail(line, "the CDATA section opened here is not closed");
            pos_ += 9;
            current.text.append(text_, pos_, end - pos_);
            while (pos_ < end) step();
            pos_ += 3;
        } else if (lookingAt("<!DOCTYPE")) {
            fail(line_, "a DOCTYPE is not allowed (no DTD is read and no entity is expanded)");
        } else if (lookingAt("<?")) {
            fail(line_, "processing instructions ('<?...?>') are not supported");
        } else if (lookingAt("<!")) {
            fail(line_, "unexpected " + here());
        } else {
            if (open.size() >= std::size_t(kMaxDepth)) fail(line_, "elements nested deeper than " + std::to_string(kMaxDepth) + " levels");
            Element child;
            if (parseStartTag(child)) {
                current.children.push_back(std::move(child));
            } else {
                open.push_back(std::move(child));  // `current` is not used past this point
            }
        }
    }
    skipMisc("after");
    if (peek() == '<') fail(line_, "an element after the root element " + tag(root.name) + " (a document has one root)");
    if (peek() != '\0') fail(line_, "text after the root element " + tag(root.name) + ": " + here());
    return root;
}

// "<?xml version="1.0" encoding="UTF-8"?>": the text is read as UTF-8 whatever it says, so
// another encoding is refused rather than misread.
void Parser::parseDeclaration()
{
    Element declaration;
    declaration.line = line_;
    declaration.name = "?xml";
    pos_ += 5;
    parseAttributes(declaration, true);
    for (const auto& [name, value] : declaration.attributes) {
        if (name == "encoding") {
            if (!equalIgnoringCase(value, "UTF-8") && !equalIgnoringCase(value, "US-ASCII"))
                fail(declaration.line, "the encoding " + quoted(value) + " is not supported (UTF-8 only)");
        } else if (name != "version" && name != "standalone") {
            fail(declaration.line, "unknown attribute " + quoted(name) + " in the XML declaration");
        }
    }
}

// Blanks and comments before or after the root element.
void Parser::skipMisc(const char* where)
{
    for (;;) {
        skipSpace();
        if (lookingAt("<!--")) {
            skipComment();
        } else if (lookingAt("<!DOCTYPE")) {
            fail(line_, "a DOCTYPE is not allowed (no DTD is read and no entity is expanded)");
        } else if (lookingAt("<?xml") && isSpace(peek(5))) {
            fail(line_, "the XML declaration must be at the very start of the text");
        } else if (lookingAt("<?")) {
            fail(line_, std::string("processing instructions ('<?...?>') are not supported (") + where + " the root element)");
        } else {
            return;
        }
    }
}

void Parser::skipComment()
{
    const int line = line_;
    pos_ += 4;  // "<!--"
    for (;;) {
        if (peek() == '\0') fail(line, "the comment opened here is not closed");
        if (lookingAt("--")) {
            if (peek(2) != '>') fail(line_, "'--' inside a comment");
            pos_ += 3;
            return;
        }
        step();
    }
}

std::string_view Parser::scanName()
{
    const std::size_t start = pos_;
    if (isNameStart(peek()))
        while (isNameChar(peek())) ++pos_;
    return std::string_view(text_).substr(start, pos_ - start);
}

// The start tag at pos_ ('<'); true if it was self-closing ("<a/>").
bool Parser::parseStartTag(Element& element)
{
    element.line = line_;
    ++pos_;
    const std::string_view name = scanName();
    if (name.empty()) fail(line_, "expected an element name after '<', found " + here());
    element.name = name;
    return parseAttributes(element, false);
}

// Attributes up to '>' or "/>" (or "?>" for the declaration); true if the tag closed itself.
bool Parser::parseAttributes(Element& element, bool declaration)
{
    const std::string what = declaration ? "the XML declaration" : "the start tag " + tag(element.name);
    // Names are views of text_, which does not change while parsing.
    std::unordered_set<std::string_view> names;
    for (;;) {
        const bool spaced = skipSpace();
        if (peek() == '\0') fail(element.line, what + " opened here is not closed");
        if (declaration) {
            if (lookingAt("?>")) {
                pos_ += 2;
                return true;
            }
        } else if (peek() == '>') {
            ++pos_;
            return false;
        } else if (lookingAt("/>")) {
            pos_ += 2;
            return true;
        }
        const std::string_view name = scanName();
        if (name.empty()) fail(line_, "unexpected " + here() + " in " + what);
        if (!spaced) fail(line_, "the attribute " + quoted(name) + " must be separated from what precedes it by a space");
        if (!names.insert(name).second) fail(line_, "the attribute " + quoted(name) + " is repeated in " + what);
        skipSpace();
        if (peek() != '=') fail(line_, "expected '=' after the attribute " + quoted(name) + ", found " + here());
        ++pos_;
        skipSpace();
        const char quote = peek();
        if (quote != '"' && quote != '\'') fail(line_, "the value of the attribute " + quoted(name) + " must be quoted");
        const int valueLine = line_;
        ++pos_;
        std::string value;
        for (;;) {
            const char c = peek();
            if (c == '\0') fail(valueLine, "the value of the attribute " + quoted(name) + " is not closed");
            if (c == quote) break;
            if (c == '<') fail(line_, "'<' inside the value of the attribute " + quoted(name) + " (write &lt;)");
            if (c == '&') {
                readReference(value);
                continue;
            }
            // XML's attribute-value normalization: a literal tab or line break reads as a space.
            value += (c == '\t' || c == '\n') ? ' ' : c;
            step();
        }
        ++pos_;
        element.attributes.emplace_back(std::string(name), std::move(value));
    }
}

void Parser::parseEndTag(const Element& open)
{
    const int line = line_;
    pos_ += 2;  // "</"
    const std::string_view name = scanName();
    if (name.empty()) fail(line, "expected an element name after '</', found " + here());
    skipSpace();
    if (peek() != '>') fail(line_, "expected '>' to end the tag " + tag(name, "</") + ", found " + here());
    ++pos_;
    if (name != open.name)
        fail(line, tag(name, "</") + " closes " + tag(open.name) + " opened at line " + std::to_string(open.line));
}

// "&lt;", "&#955;", "&#x3BB;" at pos_, appended as the character it names. No other entity
// exists without a DTD, and a DTD is never read.
void Parser::readReference(std::string& out)
{
    constexpr std::size_t kLongest = 12;  // "&#x0010FFFF;" with leading zeros to spare
    std::size_t end = pos_ + 1;
    while (end < text_.size() && end - pos_ <= kLongest && text_[end] != ';' && !isSpace(text_[end]) && text_[end] != '<' &&
           text_[end] != '&')
        ++end;
    if (charAt(end) != ';') fail(line_, "'&' must start an entity such as '&amp;', found " + here());
    const std::string_view body = std::string_view(text_).substr(pos_ + 1, end - pos_ - 1);
    const std::string_view named[][2] = {{"lt", "<"}, {"gt", ">"}, {"amp", "&"}, {"quot", "\""}, {"apos", "'"}};
    for (const auto& entity : named) {
        if (body == entity[0]) {
            out += entity[1];
            pos_ = end + 1;
            return;
        }
    }
    if (body.size() < 2 || body[0] != '#')
        fail(line_, "unknown entity " + quoted("&" + std::string(body) + ";") +
                        " (only &lt; &gt; &amp; &quot; &apos; and character references; no DTD is read)");
    const bool hex = body[1] == 'x';
    const std::string_view digits = body.substr(hex ? 2 : 1);
    std::uint32_t codePoint = 0;
    bool valid = !digits.empty();
    for (const char d : digits) {
        int value = -1;
        if (isDigit(d)) value = d - '0';
        else if (hex && lowerAscii(d) >= 'a' && lowerAscii(d) <= 'f') value = lowerAscii(d) - 'a' + 10;
        if (value < 0) valid = false;
        // At most 11 characters: the value stays far below 2^32 before this cap.
        if (valid && codePoint <= 0x10FFFF) codePoint = codePoint * (hex ? 16 : 10) + std::uint32_t(value);
    }
    if (!valid || !isXmlChar(codePoint))
        fail(line_, "the character reference " + quoted("&" + std::string(body) + ";") + " does not name an XML character");
    zcheck::text::appendUtf8(out, codePoint);
    pos_ = end + 1;
}

}  // namespace

const Element* Element::child(const std::string& wanted) const
{
    for (const Element& c : children)
        if (c.name == wanted) return &c;
    return nullptr;
}

const Element* Element::childIgnoringCase(const std::string& wanted) const
{
    for (const Element& c : children)
        if (equalIgnoringCase(c.name, wanted)) return &c;
    return nullptr;
}

const std::string* Element::attribute(const std::string& wanted) const
{
    for (const auto& [key, value] : attributes)
        if (key == wanted) return &value;
    return nullptr;
}

Element parse(std::string_view text, const std::string& source)
{
    return Parser(text, source).parseDocument();
}

}  // namespace zcheck::xml
