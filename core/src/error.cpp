#include "zcheck/error.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace zcheck {

Error::Error(const std::string& message) : std::runtime_error(message) {}

std::string printableExcerpt(std::string_view text, std::size_t maxChars)
{
    std::string out;
    for (char c : text.substr(0, maxChars)) out += (c >= 32 && c < 127) ? c : '?';
    return out;
}

std::string joinedNames(const std::vector<std::string>& names)
{
    std::string text;
    for (const auto& name : names) text += (text.empty() ? "" : ", ") + name;
    return text;
}

std::string formatNumber(double value)
{
    if (std::isnan(value)) return "nan";
    if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.17g", value);
    // Prefer the shortest form that reads back to the same double, written without an exponent
    // when the magnitude is one a person writes out (180, not 1.8e+02).
    const double magnitude = std::abs(value);
    const bool plain = magnitude == 0 || (magnitude >= 1e-4 && magnitude < 1e15);
    for (int precision = 1; precision <= 17; ++precision) {
        char shorter[32];
        std::snprintf(shorter, sizeof shorter, "%.*g", precision, value);
        if (std::strtod(shorter, nullptr) != value) continue;
        if (!plain || !std::strchr(shorter, 'e')) return shorter;
    }
    return buffer;
}

std::string fourSignificantDigits(double value)
{
    char text[32];
    std::snprintf(text, sizeof text, "%.4g", value);
    return text;
}

}  // namespace zcheck
