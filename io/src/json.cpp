#include "zcheck/detail/json.h"

#include "zcheck/error.h"

#include <algorithm>
#include <cctype>
#include <regex>
#include <vector>

namespace zcheck {

using nlohmann::json;

json parseJsonStrictly(const std::string& text, const std::string& source)
{
    // A key twice in one object is an error: nlohmann keeps the last silently, and the
    // user who wrote the first would never know it was ignored. The message names the key by
    // its path ("projection.near"), as the camera file's other messages do.
    struct Open {
        bool isObject;
        std::vector<std::string> keys;  // objects: the keys so far; the last one is being read
    };
    std::vector<Open> open;
    std::string duplicate;
    const json::parser_callback_t callback = [&](int, json::parse_event_t event, json& parsed) {
        using Event = json::parse_event_t;
        if (event == Event::object_start || event == Event::array_start) open.push_back({event == Event::object_start, {}});
        if ((event == Event::object_end || event == Event::array_end) && !open.empty()) open.pop_back();
        if (event == Event::key && !open.empty() && duplicate.empty()) {
            auto& keys = open.back().keys;
            const std::string key = parsed.get<std::string>();
            if (std::find(keys.begin(), keys.end(), key) != keys.end()) {
                for (std::size_t level = 0; level + 1 < open.size(); ++level)
                    duplicate += open[level].isObject && !open[level].keys.empty() ? open[level].keys.back() + "." : "[].";
                duplicate += key;
            }
            keys.push_back(key);
        }
        return true;
    };
    json document;
    try {
        document = json::parse(text, callback);
    } catch (const json::exception& e) {  // syntax errors, and numbers out of range such as 1e400
        std::string what = e.what();
        const std::size_t bracket = what.find(']');
        what = bracket == std::string::npos ? what : what.substr(bracket + 2);
        for (char& c : what)
            if (c == '\n' || c == '\r') c = ' ';
        throw Error(source + " is not valid JSON: " + what);
    }
    if (!duplicate.empty()) throw Error(source + ": key '" + duplicate + "' appears twice in one object");
    return document;
}

std::string prettyJson(const nlohmann::json& document)
{
    const std::string text = document.dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
    // An array whose elements are all numbers (or null) is folded onto one line; text inside
    // strings (file names, explanations such as "[-1,1]") is copied as it is.
    static const std::regex numberArray(R"(\[(\s*(-?[0-9][0-9.eE+-]*|null)\s*,)*\s*(-?[0-9][0-9.eE+-]*|null)\s*\])");
    std::string out;
    out.reserve(text.size());
    bool inString = false;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (inString) {
            out += c;
            if (c == '\\' && i + 1 < text.size()) out += text[++i];  // an escaped character, quotes included
            else if (c == '"') inString = false;
            continue;
        }
        std::smatch match;
        if (c == '[' && std::regex_search(text.cbegin() + std::ptrdiff_t(i), text.cend(), match, numberArray,
                                          std::regex_constants::match_continuous)) {
            for (char k : match.str())
                if (k == ',') out += ", ";
                else if (!std::isspace(static_cast<unsigned char>(k))) out += k;
            i += std::size_t(match.length()) - 1;
            continue;
        }
        inString = c == '"';
        out += c;
    }
    return out;
}

}  // namespace zcheck
