#include "harness/common/json_check.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "harness/common/errors.h"

namespace iblcheck {

namespace {

bool has_type(const nlohmann::json& v, JsonType type) {
    switch (type) {
    case JsonType::string: return v.is_string();
    case JsonType::number: return v.is_number();
    case JsonType::boolean: return v.is_boolean();
    case JsonType::object: return v.is_object();
    case JsonType::array: return v.is_array();
    }
    return false;
}

} // namespace

const char* JsonChecker::type_phrase(JsonType type) {
    switch (type) {
    case JsonType::string: return "a string";
    case JsonType::number: return "a number";
    case JsonType::boolean: return "true or false";
    case JsonType::object: return "an object";
    case JsonType::array: return "an array";
    }
    return "?";
}

void JsonChecker::fail(const std::string& where, const std::string& problem) const {
    throw InputError(fmt::format("{}: {}{}{}", file_, where, where.empty() ? "" : ": ", problem));
}

std::string JsonChecker::str(const nlohmann::json& v, const std::string& where) const {
    if (!v.is_string()) fail(where, fmt::format("must be a string, not {}", v.type_name()));
    return v.get<std::string>();
}

double JsonChecker::num(const nlohmann::json& v, const std::string& where) const {
    if (!v.is_number()) fail(where, fmt::format("must be a number, not {}", v.type_name()));
    return v.get<double>();
}

bool JsonChecker::boolean(const nlohmann::json& v, const std::string& where) const {
    if (!v.is_boolean()) fail(where, fmt::format("must be true or false, not {}", v.type_name()));
    return v.get<bool>();
}

void JsonChecker::keys(const nlohmann::json& j, const std::string& where, const std::set<std::string>& allowed) const {
    if (!j.is_object()) fail(where, fmt::format("must be an object, not {}", j.type_name()));
    for (auto& [k, v] : j.items())
        if (!allowed.count(k)) fail(where + "." + k, fmt::format("unknown key; valid: {}", fmt::join(allowed, ", ")));
}

const nlohmann::json* JsonChecker::member(const nlohmann::json& obj, const std::string& where, const char* key, JsonType type,
                                          bool required) const {
    auto it = obj.find(key);
    if (it == obj.end() || it->is_null()) {
        if (required) fail(where, fmt::format("missing key '{}'", key));
        return nullptr;
    }
    if (!has_type(*it, type)) fail(where, fmt::format("'{}' must be {}, not {}", key, type_phrase(type), it->type_name()));
    return &*it;
}

} // namespace iblcheck
