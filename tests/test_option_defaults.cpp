// Option defaults live in the option table only (issue 31): typed, per reader where they differ
// (cube_size 128, sampled 256), the help text made from them, and every read in the product code
// taking its default from the table, so no call site can restate one that drifts.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include "renderers/option_table.h"
#include "renderers/renderer.h"
#include "renderers/scenes/scene.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using namespace iblcheck;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_option_defaults {

namespace {
// One read of an option in the product code: where, how (the accessor) and the key.
struct Read {
    std::string where, accessor, key;
    bool computed_default; // get_*(key).value_or(...): the reader supplies the default
};

std::vector<Read> reads_in_product_code(std::vector<std::string>& inline_defaults) {
    const std::regex table_read(R"re(option_(int|double|string|vec3|choice)\(([^,;]+),\s*"(\w+)")re");
    const std::regex map_read(R"re(\.get_(int|double|string|vec3|bool|choice)\(\s*"(\w+)"\s*(,|\)(\s*\.value_or\()?))re");
    std::vector<Read> out;
    for (const char* folder : {"kernel", "image_io", "metrics", "renderers", "results", "reports", "harness", "cli"})
        for (const auto& e : fs::recursive_directory_iterator(fs::path(IBLCHECK_SOURCE_DIR) / folder)) {
            const std::string ext = e.path().extension().string();
            if ((ext != ".cpp" && ext != ".h") || e.path().stem().string().ends_with("_test")) continue; // unit tests beside code
            std::ifstream in(e.path());
            std::string line;
            for (int n = 1; std::getline(in, line); ++n) {
                const std::string where = fs::relative(e.path(), IBLCHECK_SOURCE_DIR).string() + ":" + std::to_string(n);
                for (std::sregex_iterator m(line.begin(), line.end(), table_read), end; m != end; ++m)
                    out.push_back({where, (*m)[1], (*m)[3], false});
                for (std::sregex_iterator m(line.begin(), line.end(), map_read), end; m != end; ++m) {
                    if ((*m)[3] == ",")
                        inline_defaults.push_back(where + ": " + m->str());
                    else
                        out.push_back({where, "get_" + (*m)[1].str(), (*m)[2], (*m)[4].matched});
                }
            }
        }
    return out;
}

// The type option_<accessor> reads, as an index of OptionValue's alternatives.
size_t alternative_of(const std::string& accessor) {
    if (accessor == "int") return 1;
    if (accessor == "double") return 2;
    if (accessor == "string" || accessor == "choice") return 3;
    return 4; // vec3
}
} // namespace

// The old code restated a default at 65 of its 75 reads (o.get_int("cube_size", 256) in the sampled
// renderer, 128 in the mobile one, "0.05" for bumpy_sphere's roughness, ...) while the table held prose.
TEST(OptionDefaults, EveryReadInTheProductCodeTakesItsDefaultFromTheTable) {
    std::vector<std::string> inline_defaults;
    const std::vector<Read> reads = reads_in_product_code(inline_defaults);
    for (const auto& d : inline_defaults) ADD_FAILURE() << d << ": a default at the call site (read it with option_*)";
    EXPECT_GE(reads.size(), 55u); // the scan sees the reads (renderers, harness, cli)
    std::set<std::string> keys;
    for (const Read& r : reads) {
        if (r.key == "constant") continue; // environment.cpp parses `constant:r,g,b` with an OptionMap, no option
        keys.insert(r.key);
        const OptionInfo* info = nullptr;
        for (const auto& o : option_catalog())
            if (o.key == r.key) info = &o;
        if (!info) {
            ADD_FAILURE() << r.where << ": option '" << r.key << "' is read but not in the option table";
            continue;
        }
        const bool computed = std::holds_alternative<std::monostate>(info->defaults.value);
        if (r.accessor.rfind("get_", 0) == 0) {
            // A raw read is for a set value (after has(), or a default of text such as rgbm_range=peak
            // checked first) or a computed default, which the row must say it is.
            if (r.computed_default) {
                EXPECT_TRUE(computed) << r.where << ": " << r.key << " has a default in the table";
            }
            continue;
        }
        EXPECT_FALSE(computed) << r.where << ": " << r.key << "'s default is computed by its reader (" << info->defaults.note
                               << "): read it with get_*";
        EXPECT_EQ(info->defaults.value.index(), alternative_of(r.accessor))
            << r.where << ": option_" << r.accessor << " reads " << r.key << ", whose default is another type";
        EXPECT_EQ(r.accessor == "choice", info->enumerated()) << r.where << ": " << r.key;
    }
    // And every row is read somewhere by its key (no row left describing nothing); the enumerations
    // with a define are read by shader_selections() through the table itself.
    for (const auto& o : option_catalog())
        if (o.glsl_define.empty()) {
            EXPECT_TRUE(keys.count(o.key)) << o.key << ": in the table, read nowhere";
        }
}

TEST(OptionDefaults, DifferPerReaderAndPerOtherOption) {
    OptionMap none;
    EXPECT_EQ(option_int(none, "cube_size", "mobile"), 128);
    EXPECT_EQ(option_int(none, "cube_size", "sampled"), 256);
    EXPECT_EQ(option_int(none, "ssaa", "mobile"), 2);
    EXPECT_EQ(option_int(none, "ssaa", "sampled"), 2);
    OptionMap fragment;
    fragment.set("shading", "fragment");
    EXPECT_EQ(ssaa_of(fragment), 1);
    EXPECT_EQ(option_choice(none, "integrator"), "quadrature");
    OptionMap spp;
    spp.set("spp", "64");
    EXPECT_EQ(option_choice(spp, "integrator"), "monte_carlo");
    EXPECT_EQ(option_double(none, "roughness", "sphere"), 0.5);
    EXPECT_EQ(option_double(none, "roughness", "bumpy_sphere"), 0.05);
    EXPECT_EQ(option_double(none, "metallic", "sphere_field"), 1.0);
    EXPECT_EQ(option_vec3(none, "base_color", "bumpy_sphere").y, 0.93f);
    // A set value wins over every default; a malformed one names its key.
    OptionMap set;
    set.set("cube_size", "64");
    EXPECT_EQ(option_int(set, "cube_size", "sampled"), 64);
    set.set("cube_size", "6.5");
    EXPECT_THROW(option_int(set, "cube_size", "sampled"), UsageError);
    // Programming errors: no reader where the default depends on it, the wrong type, an unknown key.
    EXPECT_THROW(option_int(none, "cube_size", ""), std::logic_error);
    EXPECT_THROW(option_double(none, "cube_size", "mobile"), std::logic_error);
    EXPECT_THROW(option_int(none, "mips", "mobile"), std::logic_error);
    EXPECT_THROW(option_int(none, "cube_sizes", "mobile"), std::logic_error);
}

// The scenes build from the table's defaults: bumpy_sphere and sphere_field are smooth metal, the rest
// the white dielectric of roughness 0.5.
TEST(OptionDefaults, ScenesUseTheirRowsOfTheTable) {
    const OptionMap none;
    EXPECT_EQ(build_scene("sphere", none).spheres[0].material.roughness, 0.5f);
    EXPECT_EQ(build_scene("grazing", none).spheres[0].material.metallic, 0.0f);
    const Sphere bumpy = build_scene("bumpy_sphere", none).spheres[0];
    EXPECT_EQ(bumpy.material.roughness, 0.05f);
    EXPECT_EQ(bumpy.material.base_color.x, 0.95f);
    EXPECT_EQ(bumpy.bump_amplitude, 0.0008f);
    EXPECT_EQ(bumpy.bump_frequency, 200.0f);
    EXPECT_EQ(build_scene("sphere_field", none).spheres[0].material.metallic, 1.0f);
}

// Each case names a reader that exists (a method or a scene), another option's value, or "key set";
// its value has the row's type; an enumeration's default is one of its values.
TEST(OptionDefaults, CasesNameRealReadersAndKeepTheRowsType) {
    std::set<std::string> readers;
    for (const auto& m : method_catalog()) readers.insert(m.name);
    for (const auto& s : scene_catalog()) readers.insert(s.name);
    for (const auto& o : option_catalog()) {
        if (o.enumerated()) {
            ASSERT_TRUE(std::holds_alternative<std::string>(o.defaults.value)) << o.key;
            EXPECT_EQ(o.choices().front(), std::get<std::string>(o.defaults.value)) << o.key;
        }
        if (std::holds_alternative<std::monostate>(o.defaults.value)) {
            EXPECT_FALSE(o.defaults.note.empty()) << o.key;
        }
        for (const DefaultCase& c : o.defaults.cases) {
            EXPECT_EQ(c.value.index(), o.defaults.value.index()) << o.key << " when " << c.when;
            const size_t eq = c.when.find('=');
            if (c.when.size() > 4 && c.when.substr(c.when.size() - 4) == " set") {
                EXPECT_NO_THROW(option_info(c.when.substr(0, c.when.size() - 4))) << o.key << " when " << c.when;
            } else if (eq != std::string::npos) {
                const auto choices = option_info(c.when.substr(0, eq)).choices();
                EXPECT_NE(std::find(choices.begin(), choices.end(), c.when.substr(eq + 1)), choices.end()) << c.when;
            } else {
                EXPECT_TRUE(readers.count(c.when)) << o.key << " when " << c.when << ": no such method or scene";
            }
        }
    }
}

// `iblcheck list` prints each option's default from the typed values, cases included.
TEST(OptionDefaults, ListShowsEveryDefault) {
    EXPECT_EQ(option_info("cube_size").default_text(), "128 (sampled: 256)");
    EXPECT_EQ(option_info("ssaa").default_text(), "2 (shading=fragment: 1)");
    EXPECT_EQ(option_info("mips").default_text(), "the full chain");
    EXPECT_EQ(option_info("bump_amplitude").default_text(), "0.0008");
    EXPECT_EQ(option_info("mix_largest_weight").default_text(), "10000");
    EXPECT_EQ(option_info("integrator").default_text(), "quadrature (spp set: monte_carlo)");
    EXPECT_EQ(option_info("base_color").default_text(), "1,1,1 (bumpy_sphere: 0.95,0.93,0.88; sphere_field: 0.95,0.93,0.88)");
    FILE* p = popen((testutil::built("iblcheck") + " list 2>&1").c_str(), "r");
    ASSERT_NE(p, nullptr);
    std::string out;
    char buf[4096];
    for (size_t n; (n = fread(buf, 1, sizeof buf, p)) > 0;) out.append(buf, n);
    ASSERT_EQ(pclose(p), 0) << out;
    for (const auto& o : option_catalog()) {
        const size_t at = out.find("\n  " + o.key + " ", out.find("\noptions ")); // the options' section
        if (o.internal) {
            EXPECT_EQ(at, std::string::npos) << o.key << ": internal, not listed";
            continue;
        }
        ASSERT_NE(at, std::string::npos) << o.key << " not listed:\n" << out;
        const std::string line = out.substr(at + 1, out.find('\n', at + 1) - at - 1);
        EXPECT_NE(line.find("default " + o.default_text()), std::string::npos) << line;
    }
}
} // namespace test_option_defaults
