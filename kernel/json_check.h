// Checks of JSON read from a file (suite files, results JSON) that fail with an InputError naming
// the file, where in it, and the problem: "suites/ci.json: tests[3].size: must be a string, not
// number". One checker for every reader, so they all word their errors the same way.
#pragma once
#include <set>
#include <string>

#include <nlohmann/json.hpp>

namespace iblcheck {

// Reads a JSON file that must be a regular file (input_file.h). A syntax error or a number beyond a
// double's range (1e400) throws InputError "<file>: <where>: not valid JSON: <why>", where <where> is
// the place the parser stopped, written as the checks below write it ("tests[0].max_cost_growth").
nlohmann::json parse_json_file(const std::string& file);

enum class JsonType { string, number, boolean, object, array };

class JsonChecker {
  public:
    explicit JsonChecker(std::string file) : file_(std::move(file)) {}
    const std::string& file() const { return file_; }

    // Throws InputError "<file>: <where>: <problem>" ("<file>: <problem>" when `where` is empty).
    [[noreturn]] void fail(const std::string& where, const std::string& problem) const;

    // The value `v`, found at `where`, must have a type: "must be a string, not number".
    std::string str(const nlohmann::json& v, const std::string& where) const;
    double num(const nlohmann::json& v, const std::string& where) const;
    bool boolean(const nlohmann::json& v, const std::string& where) const;
    // `j` must be an object whose keys are all in `allowed`: "<where>.<key>: unknown key; valid: a, b".
    void keys(const nlohmann::json& j, const std::string& where, const std::set<std::string>& allowed) const;

    // Key `key` of the object `obj` found at `where`: nullptr when absent or null (or "missing key
    // '<key>'" when `required`); "'<key>' must be a number, not string" when of the wrong type.
    const nlohmann::json* member(const nlohmann::json& obj, const std::string& where, const char* key, JsonType type,
                                 bool required = false) const;

    // "a string", "a number", "true or false", "an object", "an array".
    static const char* type_phrase(JsonType type);

  private:
    std::string file_;
};

} // namespace iblcheck
