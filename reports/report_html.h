// Internal to the report (report_writer.cpp, report_card.cpp, report_viewer.cpp, report_charts.cpp,
// since_baselines.cpp): lenient JSON
// accessors (the results are validated before rendering), the image copier, and the pieces of the
// page each file writes.
#pragma once
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "reports/failure_groups.h"
#include "reports/float_data.h"
#include "reports/svg_chart.h"

namespace iblcheck::report::html {

using json = nlohmann::json;

std::string str(const json& j, const char* k);
std::optional<double> num(const json& j, const char* k);
const json& sub(const json& j, const char* k);
inline std::string e(std::string_view s) { return html_escape(s); }
std::string value_text(const json& v);

// A run's commit as the page names it: "abc1234" or "abc1234+dirty".
std::string run_commit(const json& r);

// fail, error, missing-golden, improved, pass: the order of the page.
const std::vector<std::string>& verdict_order();
int verdict_rank(const std::string& v);
bool needs_bless(const std::string& v);

// One colour per method (the charts and the tiles).
std::string method_color(const std::string& method);

// "t-3": the id of the test card at `i` in page order.
std::string test_id(size_t i);
// What differs between tests of one scene and environment: "mobile dominant_dir=lagarde".
std::string test_label(const json& t);
// The option key a variant changes ("dominant_dir"; "default" for none; "a+b" for several).
std::string variant_family(const json& t);
std::string short_message(const std::string& m);

// Copies the images the page shows next to index.html (same relative paths) so the report folder
// is self-contained; remembers the missing ones.
class ImageStore {
  public:
    ImageStore(std::filesystem::path results_dir, std::filesystem::path out_dir);
    // URL (relative to index.html) of the image, or nullopt when the file is missing.
    std::optional<std::string> url(const std::string& rel);
    const std::vector<std::string>& missing() const { return missing_; }
    bool exists(const std::string& rel) const;

  private:
    std::filesystem::path results_dir_, out_dir_;
    std::map<std::string, std::optional<std::string>> done_;
    std::vector<std::string> missing_;
    int external_ = 0;
};

struct Trend {
    Sparkline flip, frame, cost;
    std::string verdict_strip;
    bool any = false;
};

struct PageContext {
    ImageStore& images;
    DataStore& data;
};

// What the image viewer shows: a test image against a golden, with the FLIP heatmap.
struct ViewerSpec {
    std::string test_png, golden_png, heat_png; // as in results.json
    std::string test_exr, golden_exr, error_exr;
    std::string golden_name = "golden"; // "baseline", "reference"
    std::optional<int> block_x, block_y;
    std::string block_sphere;
    double tol = 0.05;
    std::string tol_note; // where the threshold comes from
};
// The image viewer (report_viewer.cpp): the PNGs, and canvases over the float data for the script.
void viewer_html(std::string& o, PageContext& ctx, const json& t, const ViewerSpec& vs);

// A test's full card (<section class="test ...">): expanded for what needs a look, folded (hidden,
// opened from its tile) for a pass.
void test_card(std::string& o, const json& t, size_t idx, PageContext& ctx, const Trend& trend, bool expanded);
// Failures that share a cause (failure_groups.h), group `k` (report_groups.cpp): what they share,
// the group's one approve command, the representative's card expanded, the others' tiles folded in a
// <details> (each opens its card).
void group_section(std::string& o, const std::vector<const json*>& tests, const FailureGroup& g, size_t k,
                   const std::string& bless_line, PageContext& ctx, const std::vector<Trend>& trends);
// A passing test's thumbnail tile in the grid; clicking it opens the card.
void test_tile(std::string& o, const json& t, size_t idx, PageContext& ctx);

// The summary's table of what changed since the baselines were blessed (since_baselines.cpp):
// shader tree, commit, driver and CPU class, blessed with and now; "" when no baseline was judged.
std::string since_baselines_html(const json& results, const std::vector<const json*>& tests);

// The change (%) of a test's mean FLIP against the truth since the latest earlier run in `runs`
// (history entries, oldest first, this run last) that measured it; nullopt without one.
std::optional<double> accuracy_drift(const std::vector<const json*>& runs, const std::string& test);
// The table of all tests (report_table.cpp): verdict, name, FLIP vs golden and vs the truth, drift,
// cost, times, message; numeric columns sort on a click (data-sort, the script). drift[i]: test i's.
std::string tests_table(const std::vector<const json*>& tests, const std::vector<std::optional<double>>& drift);

// The charts tab: cost against accuracy, wall time (median and range), error against roughness,
// flicker against FLIP, each as small multiples. tests[i] is the page's test i (its id test_id(i)).
std::string charts_html(const std::vector<const json*>& tests);
// Linear against display scoring (report_display_chart.cpp): "" when no test was scored in a display space.
std::string display_section(const std::vector<const json*>& tests);
// Spearman's rank correlation of two series (ties: mean ranks); NaN under 2 values or a constant one.
double spearman_rho(const std::vector<double>& a, const std::vector<double>& b);

} // namespace iblcheck::report::html
