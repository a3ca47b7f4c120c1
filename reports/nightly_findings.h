// What a nightly run found, in words and numbers, at the top of its report (issue 26):
//   - the largest share of error per environment (from `iblcheck explain --json` files), with one
//     stacked bar per sphere (a colour per rung) under the sweep image (report_budget_chart.cpp);
//   - the best configuration per cost band (the run's own mobile tests, banded by SPIR-V
//     instructions per pixel against the default's; and `iblcheck explore --json`'s winner and
//     Pareto fronts when given);
//   - accuracy per method and environment against the truth, the best and worst variants;
//   - what changed since the last run (the history file, --history).
// The explain/explore files are given to the report (`iblcheck report ... --findings F`, or
// `iblcheck run ... --findings F`): a nightly run does not compute them (explain is minutes per
// environment, explore an hour), they are made by those commands and named on the command line.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace iblcheck::report {

namespace html {
class ImageStore;
}

// Reads an `iblcheck explain --json` or `iblcheck explore --json` file; InputError naming the file
// when it is unreadable, not JSON, or neither (no "rungs" with "total", no "environments").
nlohmann::json read_findings(const std::filesystem::path& file);

// Whether the page gets the findings section: the suite is "nightly" or findings were given.
bool findings_wanted(const nlohmann::json& results, const std::vector<nlohmann::json>& findings);

// The section (<section class="findings" id="findings">). `history`: as write_report's.
std::string findings_html(const nlohmann::json& results, const std::vector<nlohmann::json>& history,
                          const std::vector<nlohmann::json>& findings, html::ImageStore& images);

// One stacked bar per sphere of an explain budget (report_budget_chart.cpp): each rung's share of
// the sphere's mean FLIP, a colour per rung, positive shares stacked up from zero and negative ones
// down; <svg class="chart budget" data-chart="budget-ENV" data-points="SPHERES">, a <rect
// class="seg" data-rung="KEY"> per non-zero share.
// The bars are laid out as the sweep image lays out the spheres: a row per material (metallic value),
// `pitch` pixels a column (the image's width over its columns), so each bar stands under its sphere.
std::string budget_bars_svg(const nlohmann::json& budget, double pitch = 30);

// The section's parts read from the findings files (findings_searches.cpp); each adds its sentences
// to `words`.
std::string findings_budgets_html(const std::vector<nlohmann::json>& findings, const nlohmann::json& results,
                                  html::ImageStore& images, std::vector<std::string>& words);
std::string findings_explore_html(const std::vector<nlohmann::json>& findings, std::vector<std::string>& words);

} // namespace iblcheck::report
