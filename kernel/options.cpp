#include "options.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>

namespace iblcheck {

namespace {
std::string join(const std::vector<std::string>& v) {
    std::string out;
    for (const auto& s : v) out += (out.empty() ? "" : ", ") + s;
    return out;
}

double parse_double(const std::string& key, const std::string& text) {
    char* end = nullptr;
    errno = 0;
    double v = std::strtod(text.c_str(), &end);
    if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE || !std::isfinite(v))
        throw UsageError("option '" + key + "': '" + text + "' is not a finite number");
    // The renderers read options as 32-bit floats: 1e39 became inf (constant:1e39, an all-black
    // render that bless accepted).
    if (std::fabs(v) > double(std::numeric_limits<float>::max()))
        throw UsageError("option '" + key + "': '" + text + "' is beyond a 32-bit float's range (3.4e38)");
    return v;
}
} // namespace

void OptionMap::set_from_string(const std::string& kv) {
    auto eq = kv.find('=');
    if (eq == std::string::npos || eq == 0) throw UsageError("option '" + kv + "' is not of the form key=value");
    values_[kv.substr(0, eq)] = kv.substr(eq + 1);
}

std::optional<std::string> OptionMap::get_string(const std::string& key) const {
    auto it = values_.find(key);
    if (it == values_.end()) return std::nullopt;
    return it->second;
}

std::optional<double> OptionMap::get_double(const std::string& key) const {
    auto it = values_.find(key);
    if (it == values_.end()) return std::nullopt;
    return parse_double(key, it->second);
}

std::optional<int> OptionMap::get_int(const std::string& key) const {
    auto it = values_.find(key);
    if (it == values_.end()) return std::nullopt;
    double v = parse_double(key, it->second);
    if (v != std::floor(v) || std::fabs(v) > 1e9)
        throw UsageError("option '" + key + "': '" + it->second + "' is not an integer");
    return static_cast<int>(v);
}

std::optional<bool> OptionMap::get_bool(const std::string& key) const {
    auto it = values_.find(key);
    if (it == values_.end()) return std::nullopt;
    const std::string& s = it->second;
    if (s == "1" || s == "true" || s == "on" || s == "yes") return true;
    if (s == "0" || s == "false" || s == "off" || s == "no") return false;
    throw UsageError("option '" + key + "': '" + s + "' is not a boolean (on|off|true|false|1|0)");
}

std::optional<Vec3f> OptionMap::get_vec3(const std::string& key) const {
    auto it = values_.find(key);
    if (it == values_.end()) return std::nullopt;
    std::vector<double> parts;
    std::stringstream ss(it->second);
    std::string item;
    while (std::getline(ss, item, ',')) parts.push_back(parse_double(key, item));
    if (parts.size() == 1) return Vec3f{float(parts[0]), float(parts[0]), float(parts[0])};
    if (parts.size() == 3) return Vec3f{float(parts[0]), float(parts[1]), float(parts[2])};
    throw UsageError("option '" + key + "': '" + it->second + "' needs 1 or 3 comma-separated numbers");
}

std::optional<std::string> OptionMap::get_choice(const std::string& key, const std::vector<std::string>& allowed) const {
    auto v = get_string(key);
    if (!v) return std::nullopt;
    for (const auto& a : allowed)
        if (a == *v) return v;
    throw UsageError("option '" + key + "': unknown value '" + *v + "'; valid: " + join(allowed));
}

void OptionMap::check_known(const std::set<std::string>& known, const std::string& context) const {
    std::vector<std::string> unknown;
    for (const auto& [k, v] : values_)
        if (!known.count(k)) unknown.push_back(k);
    if (unknown.empty()) return;
    throw UsageError("unknown option(s) for " + context + ": " + join(unknown) +
                     "; valid: " + join(std::vector<std::string>(known.begin(), known.end())));
}

std::string OptionMap::canonical() const {
    std::string out;
    for (const auto& [k, v] : values_) out += (out.empty() ? "" : ",") + k + "=" + v;
    return out;
}

} // namespace iblcheck
