#include "zcheck/depth_map_reading.h"

#include "zcheck/detail/depth_map_json.h"
#include "zcheck/input_file.h"

#include "zcheck/error.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
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

double MapAccuracy::requireDeclared(double value, const std::string& name, bool relative)
{
    if (!(value >= 0) || !std::isfinite(value) || (relative && value >= 1))
        throw Error(name + " must be a finite number >= 0" + (relative ? " and below 1" : "") + ", got " +
                    formatNumber(value));
    return value;
}

void MapAccuracy::require(const std::string& where) const
{
    requireDeclared(quantum, where + ": quantum", false);
    requireDeclared(relative, where + ": relative tolerance", true);
    requireDeclared(absolute, where + ": absolute tolerance", false);
}

NoiseModel NoiseModel::parse(const std::string& text, const std::string& name)
{
    auto refuse = [&]() -> NoiseModel {
        throw Error(name + " must be kinect, A+B*z^2 or A+B*(z-C)^2 with finite A, B >= 0 (not both 0) and C, got '" +
                    text + "'");
    };
    std::string t;
    for (char c : text)
        if (!std::isspace(static_cast<unsigned char>(c))) t += char(std::tolower(static_cast<unsigned char>(c)));
    if (t == "kinect") return {0.0012, 0.0019, 0.4};
    // A number at the front of `rest`, consumed; nullopt without one.
    auto number = [](std::string& rest) -> std::optional<double> {
        std::size_t used = 0;
        double v = 0;
        try {
            v = std::stod(rest, &used);
        } catch (const std::exception&) {
            return std::nullopt;
        }
        rest = rest.substr(used);
        return v;
    };
    std::string rest = t;
    NoiseModel out;
    const std::optional<double> a = number(rest);
    if (!a || rest.empty() || rest[0] != '+') return refuse();
    rest = rest.substr(1);
    const std::optional<double> b = number(rest);
    if (!b) return refuse();
    if (rest == "*z^2") {
        out = {*a, *b, 0};
    } else if (rest.rfind("*(z-", 0) == 0) {
        rest = rest.substr(4);
        const std::optional<double> c = number(rest);
        if (!c || rest != ")^2") return refuse();
        out = {*a, *b, *c};
    } else {
        return refuse();
    }
    if (!(out.a >= 0 && out.b >= 0 && std::isfinite(out.a) && std::isfinite(out.b) && std::isfinite(out.z0)) || !out.any())
        return refuse();
    return out;
}

std::string NoiseModel::text() const
{
    if (!any()) return "";
    return formatNumber(a) + "+" + formatNumber(b) + (z0 == 0 ? "*z^2" : "*(z-" + formatNumber(z0) + ")^2");
}

void DepthMapReading::requireScale(double scale, const std::string& name)
{
    if (!(scale > 0 && std::isfinite(scale))) throw Error(name + " must be a positive finite number, got " + formatNumber(scale));
}

void DepthMapReading::requireScaleForIntegers(const std::string& path, const std::string& storage) const
{
    if (!(scale > 0))
        throw Error("depth map '" + path + "' stores integers (" + storage +
                    "): give --scale (stored value = depth × scale, e.g. 1000 for millimetres, 5000 for many RGB-D sets, 256 "
                    "for KITTI)");
}

void DepthMapReading::requireOffset(double offset, const std::string& name)
{
    if (!std::isfinite(offset)) throw Error(name + " must be a finite number, got " + formatNumber(offset));
}

void depthsFromStored(DepthMapFile& map, StoredValues stored, const DepthMapReading& reading)
{
    if (stored == StoredValues::Half) {
        map.valueStep.resize(map.value.size());
        for (std::size_t i = 0; i < map.value.size(); ++i) map.valueStep[i] = float(reading.depthStepOf(binary16Step(map.value[i])));
    }
    const bool integer = stored == StoredValues::Integer;
    for (double& v : map.value) v = reading.depthOf(v, integer);
    map.valueQuantum = integer ? 1.0 / reading.scale : 0.0;
}

std::string MapAccuracy::options() const
{
    std::string out;
    auto add = [&](const std::string& option) { out += (out.empty() ? "" : " ") + option; };
    if (quantum > 0) add("--quantum " + formatNumber(quantum));
    if (relative > 0) add("--rel-tolerance " + formatNumber(relative));
    if (absolute > 0) add("--abs-tolerance " + formatNumber(absolute));
    if (noise.any()) add("--noise-model '" + noise.text() + "'");
    if (allowHoles) add("--allow-holes");
    return out;
}

MapAccuracy MapAccuracy::over(const MapAccuracy& fallback) const
{
    MapAccuracy out = *this;
    if (!(out.quantum > 0)) out.quantum = fallback.quantum;
    if (!(out.relative > 0)) out.relative = fallback.relative;
    if (!(out.absolute > 0)) out.absolute = fallback.absolute;
    if (!out.noise.any()) out.noise = fallback.noise;
    out.allowHoles = out.allowHoles || fallback.allowHoles;
    return out;
}

MapAccuracy accuracyFromJson(const nlohmann::json& object, const std::string& where)
{
    MapAccuracy out;
    auto given = [&](const char* key) { return object.contains(key) && !object[key].is_null(); };
    auto number = [&](const char* key, double& field) {
        if (!given(key)) return;
        const nlohmann::json& v = object[key];
        if (!v.is_number() || !(v.get<double>() >= 0) || !std::isfinite(v.get<double>()))
            throw Error(where + ": \"" + key + "\" must be a finite number >= 0");
        field = v.get<double>();
    };
    number("quantum", out.quantum);
    number("rel_tolerance", out.relative);
    number("abs_tolerance", out.absolute);
    if (out.relative >= 1) throw Error(where + ": \"rel_tolerance\" must be below 1");
    if (given("noise_model")) {
        if (!object["noise_model"].is_string())
            throw Error(where + ": \"noise_model\" must be a string (kinect, A+B*z^2 or A+B*(z-C)^2)");
        out.noise = NoiseModel::parse(object["noise_model"].get<std::string>(), where + ": \"noise_model\"");
    }
    if (given("allow_holes")) {
        if (!object["allow_holes"].is_boolean()) throw Error(where + ": \"allow_holes\" must be true or false");
        out.allowHoles = object["allow_holes"].get<bool>();
    }
    return out;
}

bool isExportSidecar(const nlohmann::json& document)
{
    return document.is_object() && document.contains("zcheck_version") && document.contains("camera") &&
           document["camera"].is_object();
}

nlohmann::json toJson(const MapAccuracy& accuracy)
{
    return {{"quantum", accuracy.quantum},
            {"rel_tolerance", accuracy.relative},
            {"abs_tolerance", accuracy.absolute},
            {"noise_model", accuracy.noise.any() ? nlohmann::json(accuracy.noise.text()) : nlohmann::json(nullptr)},
            {"allow_holes", accuracy.allowHoles}};
}

double binary16Step(double stored)
{
    const double magnitude = std::abs(stored);
    if (!std::isfinite(magnitude)) return 0;
    const int exponent = magnitude < std::ldexp(1.0, -14) ? -14 : std::ilogb(magnitude);
    return std::ldexp(1.0, exponent - 10);
}

DepthMapReading withSidecar(DepthMapReading r, const std::string& sidecar)
{
    const nlohmann::json doc = parseJsonStrictly(readInputFile(sidecar, kSidecarInput), sidecar);
    if (!doc.is_object()) throw Error("sidecar '" + sidecar + "' must hold a JSON object");
    auto bad = [&](const char* key, const char* rule) { return Error("sidecar '" + sidecar + "': \"" + key + "\" " + rule); };
    auto given = [&](const char* key) { return doc.contains(key) && !doc[key].is_null(); };
    if (given("channel") && r.channel.empty()) {
        if (!doc["channel"].is_string()) throw bad("channel", "must be a channel name (a string)");
        r.channel = doc["channel"].get<std::string>();
    }
    if (given("scale") && r.scale == 0) {
        if (!doc["scale"].is_number() || !(doc["scale"].get<double>() > 0) || !std::isfinite(doc["scale"].get<double>()))
            throw bad("scale", "must be a positive finite number");
        r.scale = doc["scale"].get<double>();
    }
    if (given("offset") && !r.offset) {
        if (!doc["offset"].is_number() || !std::isfinite(doc["offset"].get<double>())) throw bad("offset", "must be a finite number");
        r.offset = doc["offset"].get<double>();
    }
    r.accuracy = r.accuracy.over(accuracyFromJson(doc, "sidecar '" + sidecar + "'"));
    if (given("miss") && !r.miss.given()) {
        const nlohmann::json& m = doc["miss"];
        if (m.is_number()) {
            char text[40];
            std::snprintf(text, sizeof text, "%.17g", m.get<double>());
            r.miss = MissRule::parse(text);
        } else if (m.is_string()) {
            try {
                r.miss = MissRule::parse(m.get<std::string>());
            } catch (const Error& e) {
                throw bad("miss", (std::string("is not a miss rule: ") + e.what()).c_str());
            }
        } else {
            throw bad("miss", "must be a number or a string such as \">=1e9\", \"nan\" or \"inf\"");
        }
    }
    return r;
}

SidecarSubject sidecarSubject(const std::string& sidecar)
{
    const nlohmann::json doc = parseJsonStrictly(readInputFile(sidecar, kSidecarInput), sidecar);
    SidecarSubject out;
    if (!doc.is_object()) return out;
    out.hasCamera = isExportSidecar(doc);
    if (!doc.contains("channels") || !doc["channels"].is_array()) return out;
    for (const nlohmann::json& channel : doc["channels"]) {
        if (!channel.is_object() || !channel.contains("name") || !channel.contains("quantity")) continue;
        if (!channel["name"].is_string() || !channel["quantity"].is_string()) continue;
        const std::string quantity = channel["quantity"].get<std::string>();
        if (quantity == "window" || quantity == "ndc" || quantity == "eye-z" || quantity == "distance")
            out.channelQuantities.emplace_back(channel["name"].get<std::string>(), quantity);
    }
    return out;
}

std::optional<std::string> SidecarSubject::quantityOf(const std::string& sidecar, const std::string& channel) const
{
    if (channelQuantities.empty()) return std::nullopt;
    std::string listed;
    for (const auto& [name, quantity] : channelQuantities) {
        if (!channel.empty() && name == channel) return quantity;
        listed += (listed.empty() ? "" : ", ") + name + " (" + quantity + ")";
    }
    if (channel.empty() && channelQuantities.size() == 1) return channelQuantities.front().second;
    if (!channel.empty()) return std::nullopt;
    throw Error("sidecar '" + sidecar + "' lists several depth channels — " + listed +
                ": give --channel or --quantity");
}

}  // namespace zcheck
