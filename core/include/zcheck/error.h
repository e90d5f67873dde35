#pragma once
// The one exception type zcheck throws at its boundaries (files, parsing, Embree and
// OpenImageIO set-up, validating factories). Its message is one line that names the file,
// key or value at fault; the command line prints it and exits with status 2.
// Hot loops never throw.
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace zcheck {

class Error : public std::runtime_error {
public:
    explicit Error(const std::string& message);
};

// "1.5", "inf", "nan": numbers in messages printed the way a user would type them back.
std::string formatNumber(double value);
// "12.35", "0.001235", "1.235e+07": four significant digits (printf's %.4g), for a measured value
// a sentence reports rather than one to be typed back exactly.
std::string fourSignificantDigits(double value);

// At most `maxChars` characters of `text` for a message, each byte outside printable ASCII
// as '?': file contents quoted in an error stay one readable line.
std::string printableExcerpt(std::string_view text, std::size_t maxChars);

// "opengl, direct3d, vulkan": the names a message says are accepted.
std::string joinedNames(const std::vector<std::string>& names);

}  // namespace zcheck
