#pragma once
// Strict JSON for every zcheck document (library zcheck::io, target zcheck_io_detail; never
// installed): the one parser that refuses a key repeated within an object, and the one printer
// for people. nlohmann-json stays out of zcheck's public interface: only zcheck's own libraries
// and programs include this header, linking `$<BUILD_INTERFACE:zcheck_io_detail>` PRIVATE.
#include <nlohmann/json.hpp>

#include <string>

namespace zcheck {

// JSON text parsed strictly: a syntax error or a key repeated within one object throws Error
// beginning with `source` (e.g. "camera file 'c.json'") and naming the key by its path.
nlohmann::json parseJsonStrictly(const std::string& text, const std::string& source);

// JSON indented for people: arrays of numbers (matrix rows, vectors) stay on one line.
// Invalid UTF-8 in strings (file names) is replaced, never thrown over.
std::string prettyJson(const nlohmann::json& document);

}  // namespace zcheck
