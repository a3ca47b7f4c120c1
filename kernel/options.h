// Options have one spelling everywhere (docs/DESIGN.md): CLI `--set key=value`, suite files, results
// JSON and the report all use the same key=value strings. OptionMap keeps them as strings and
// parses on read, so an unknown key or a malformed value is caught in one place with a message
// that names the key.
#pragma once
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "errors.h"
#include "vec3.h"

namespace iblcheck {

class OptionMap {
  public:
    OptionMap() = default;

    // Parses "key=value"; throws UsageError on a missing '='.
    void set_from_string(const std::string& kv);
    void set(const std::string& key, const std::string& value) { values_[key] = value; }
    void erase(const std::string& key) { values_.erase(key); }
    bool has(const std::string& key) const { return values_.count(key) != 0; }

    // The value of `key` parsed, or nothing when it is not set; UsageError naming the key for a
    // malformed value. No default here: an option's default lives in the option table
    // (renderers/option_table.h, option_int and friends), once.
    std::optional<std::string> get_string(const std::string& key) const;
    std::optional<double> get_double(const std::string& key) const;
    std::optional<int> get_int(const std::string& key) const;
    std::optional<bool> get_bool(const std::string& key) const;
    std::optional<Vec3f> get_vec3(const std::string& key) const; // "r,g,b" or a single value
    // A string that must be one of `allowed`; throws UsageError listing them otherwise.
    std::optional<std::string> get_choice(const std::string& key, const std::vector<std::string>& allowed) const;

    // Throws UsageError naming every key not in `known` (and listing the known ones).
    void check_known(const std::set<std::string>& known, const std::string& context) const;

    const std::map<std::string, std::string>& values() const { return values_; }
    // Stable "k1=v1,k2=v2" form, used in test names and provenance.
    std::string canonical() const;

  private:
    std::map<std::string, std::string> values_;
};

} // namespace iblcheck
