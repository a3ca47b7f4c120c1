#include "kernel/json_check.h"

#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "kernel/errors.h"
#include "kernel/input_file.h"

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

// Where the parser is, from its callback's events: "tests[2].tags".
class ParsePath {
  public:
    void on(nlohmann::json::parse_event_t event, const nlohmann::json& parsed) {
        using E = nlohmann::json::parse_event_t;
        switch (event) {
        case E::object_start: frames_.push_back({false, {}, 0}); break;
        case E::array_start: frames_.push_back({true, {}, 0}); break;
        case E::key: frames_.back().key = parsed.get<std::string>(); break;
        case E::object_end:
        case E::array_end:
            frames_.pop_back();
            element_done();
            break;
        case E::value: element_done(); break;
        }
    }
    std::string str() const {
        std::string out;
        for (const Frame& f : frames_) out += f.array ? "[" + std::to_string(f.done) + "]" : (out.empty() ? "" : ".") + f.key;
        return out.empty() ? "(top level)" : out;
    }

  private:
    struct Frame {
        bool array;
        std::string key; // objects: the key being read
        size_t done;     // arrays: elements read, so the index of the one being read
    };
    void element_done() {
        if (!frames_.empty() && frames_.back().array) ++frames_.back().done;
    }
    std::vector<Frame> frames_;
};

} // namespace

nlohmann::json parse_json_file(const std::string& file) {
    std::ifstream in = open_input_file(file);
    ParsePath path;
    try {
        return nlohmann::json::parse(in, [&path](int, nlohmann::json::parse_event_t event, nlohmann::json& parsed) {
            path.on(event, parsed);
            return true;
        });
    } catch (const nlohmann::json::exception& e) { // parse_error, and out_of_range 406 for 1e400
        throw InputError(fmt::format("{}: {}: not valid JSON: {}", file, path.str(), e.what()));
    }
}

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
