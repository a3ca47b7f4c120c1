// The one option table: every `--set key=value` a method reads, with its default, its values, the
// methods that read it and, for variants that select shader code, the GLSL define. Everything
// else derives from it: `iblcheck list`, validation of suites and command lines, the host's
// reading of options (option_int, option_double, ... below: the default comes from here and from
// nowhere else) and the defines the shaders are compiled with.
//
// Adding a variant is one row here (or one more name in a row's values) plus its shader code:
// an enumerated option with a define compiles every shader with the selection as an index
// (MIP_MAPPING 2) and every value's name as a named constant (MIP_MAPPING_UE4 0,
// MIP_MAPPING_FILAMENT 1, MIP_MAPPING_ORIGIN 2), so GLSL reads `#if MIP_MAPPING == MIP_MAPPING_ORIGIN`.
// Shaders have no fallback of their own: a missing define is a compile error, never a silent
// default that could disagree with the table.
#pragma once
#include <map>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "kernel/options.h"

namespace iblcheck {

// A default, typed as its readers read it: int (option_int), double (option_double), text
// (option_string, option_choice) or r,g,b (option_vec3). std::monostate: the reader computes it
// from other values (OptionDefault::note says how) and reads the option with OptionMap's get_*.
using OptionValue = std::variant<std::monostate, int, double, std::string, Vec3f>;

// Where a default differs from the row's: `when` is a reader (a method, "sampled", or a scene,
// "bumpy_sphere"), "key=value" (another option's value, its default included) or "key set".
struct DefaultCase {
    std::string when;
    OptionValue value;
};

struct OptionDefault {
    OptionDefault(OptionValue v, std::vector<DefaultCase> c = {}, std::string n = {})
        : value(std::move(v)), cases(std::move(c)), note(std::move(n)) {}
    OptionValue value;
    std::vector<DefaultCase> cases; // the first that holds wins
    std::string note;               // a computed default (value is std::monostate): what the reader does
};

struct OptionInfo {
    std::string key;
    OptionDefault defaults;
    std::string values;      // "ue4|filament|origin" for an enumeration; else a range or a description
    std::string methods;     // "mobile", "mobile,sampled", "all"
    std::string glsl_define; // enumerations that select shader code; empty otherwise
    std::string description;
    // Read by the code and the tests (the Monte Carlo integrator's knobs) but not accepted by
    // `--set` or a suite, and not listed: its default lives here all the same.
    bool internal = false;

    bool enumerated() const { return values.find('|') != std::string::npos; }
    std::vector<std::string> choices() const; // the values of an enumeration, default first
    bool read_by(const std::string& method) const;
    // The default as `iblcheck list` prints it, from the typed values: "128 (sampled: 256)".
    std::string default_text() const;
};

// The table, in the order `iblcheck list` prints it.
const std::vector<OptionInfo>& option_catalog();

// The row for `key`; throws std::logic_error for a key not in the table (a programming error:
// user input is checked by validate_spec() before any renderer reads it).
const OptionInfo& option_info(const std::string& key);

// "0.0008", "256", "ue4", "1,1,1": a typed value as an option's text (the spelling --set takes).
std::string option_value_text(const OptionValue& v);

// The default of `key` for `reader` (a method or a scene) given the other options in `o`. Throws
// std::logic_error when the row differs by reader and `reader` is empty.
const OptionValue& option_default(const OptionMap& o, const std::string& key, const std::string& reader);

// The value of `key` in `o`, or the table's default for `reader`; UsageError naming the key for a
// malformed value. std::logic_error when the row's default is not of the type read (a programming
// error; tests/test_option_table.cpp checks every call site's key and type).
int option_int(const OptionMap& o, const std::string& key, const std::string& reader);
double option_double(const OptionMap& o, const std::string& key, const std::string& reader);
Vec3f option_vec3(const OptionMap& o, const std::string& key, const std::string& reader);
std::string option_string(const OptionMap& o, const std::string& key, const std::string& reader);

// The value of enumerated option `key` in `o`, or the table's default; UsageError naming the key
// and the valid values for anything else.
std::string option_choice(const OptionMap& o, const std::string& key, const std::string& reader = "");

// "MIP_MAPPING_ORIGIN": the GLSL name of one value of an option with a define.
std::string glsl_value_name(const OptionInfo& info, const std::string& value);

// The defines a shader is compiled with: the named values of every option with a define, plus,
// for each (key, value) in `selections`, DEFINE = the value's index. Throws UsageError for a value
// not in the table.
std::map<std::string, std::string> glsl_defines(const std::map<std::string, std::string>& selections);

// For every option with a define that `method` reads: key -> the value in `o` (or the default).
std::map<std::string, std::string> shader_selections(const OptionMap& o, const std::string& method);

// The ssaa a mobile render uses: the option, else the table's default (2 for shading=compute, rays
// per pixel; 1 for shading=fragment, supersampling factor; MSAA covers silhouettes).
int ssaa_of(const OptionMap& o);

// The selections alone as DEFINE = value name (e.g. "STORAGE": "STORAGE_RGBA16F"): what the
// results record as the shader variant.
std::map<std::string, std::string> glsl_selection_names(const std::map<std::string, std::string>& selections);

} // namespace iblcheck
