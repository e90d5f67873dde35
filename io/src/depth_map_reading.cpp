#include "zcheck/depth_map_reading.h"

#include "zcheck/error.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <iterator>

namespace zcheck {

void refuseDepthMap(const std::string& path, const std::string& why)
{
    throw Error("cannot read depth map '" + path + "': " + why);
}

MissRule MissRule::parse(const std::string& given)
{
    std::string text = given;
    text.erase(0, text.find_first_not_of(" \t"));
    text.erase(text.find_last_not_of(" \t") + 1);
    MissRule rule;
    std::size_t at = 0;
    if (text.rfind(">=", 0) == 0) rule.test = Test::GreaterEqual, at = 2;
    else if (text.rfind("<=", 0) == 0) rule.test = Test::LessEqual, at = 2;
    else if (text.rfind(">", 0) == 0) rule.test = Test::Greater, at = 1;
    else if (text.rfind("<", 0) == 0) rule.test = Test::Less, at = 1;
    else rule.test = Test::Equal;
    std::string number = text.substr(at);
    number.erase(0, number.find_first_not_of(" \t"));
    if (!number.empty() && number[0] == '+') number.erase(0, 1);  // from_chars takes no '+'
    const auto [end, error] = std::from_chars(number.data(), number.data() + number.size(), rule.value);
    const bool isNumber = !number.empty() && error == std::errc() && end == number.data() + number.size();
    if (isNumber && std::isnan(rule.value) && rule.test == Test::Equal) rule.test = Test::IsNan;
    if (!isNumber || (rule.test != Test::Equal && rule.test != Test::IsNan && !std::isfinite(rule.value)))
        throw Error("miss value '" + given +
                    "' is neither a number (0, 65535, 1e10, nan, inf) nor a comparison with a finite number "
                    "(>=1e9, >1e9, <=0, <0)");
    rule.written_ = text;
    return rule;
}

bool MissRule::matches(double stored) const
{
    switch (test) {
    case Test::None: return false;
    case Test::Equal: return stored == value;
    case Test::IsNan: return std::isnan(stored);
    case Test::Greater: return stored > value;
    case Test::GreaterEqual: return stored >= value;
    case Test::Less: return stored < value;
    case Test::LessEqual: return stored <= value;
    }
    return false;
}

namespace {

std::string listed(const std::vector<std::string>& names)
{
    std::string out;
    for (const std::string& name : names) out += (out.empty() ? "'" : ", '") + name + "'";
    return out;
}

// Z, depth, a layer's *.Z or *.depth (any case for "depth"), or one of zcheck's own names.
bool namesDepth(const std::string& name)
{
    const std::size_t dot = name.find_last_of('.');
    std::string last = dot == std::string::npos ? name : name.substr(dot + 1);
    if (last == "Z") return true;
    for (char& c : last) c = char(std::tolower(static_cast<unsigned char>(c)));
    return last == "depth" || name == "window" || name == "ndc" || name == "distance";
}

}  // namespace

std::string chooseDepthChannel(const std::string& path, const std::vector<std::string>& names, const std::string& wanted,
                               const std::string& quantityChannel)
{
    if (!wanted.empty()) {
        if (std::find(names.begin(), names.end(), wanted) == names.end())
            refuseDepthMap(path, "it has no channel '" + wanted + "'; its channels are " + listed(names));
        return wanted;
    }
    if (names.size() == 1) return names.front();
    if (!quantityChannel.empty() && std::find(names.begin(), names.end(), quantityChannel) != names.end())
        return quantityChannel;
    std::vector<std::string> depth;
    std::copy_if(names.begin(), names.end(), std::back_inserter(depth), namesDepth);
    if (depth.size() == 1) return depth.front();
    if (depth.empty())
        refuseDepthMap(path, "none of its " + std::to_string(names.size()) + " channels (" + listed(names) +
                            ") is named as depth (Z, depth, *.Z, *.depth); name the one to read with --channel");
    refuseDepthMap(path, "several of its channels are named as depth (" + listed(depth) + "); name the one to read with --channel");
}

}  // namespace zcheck
