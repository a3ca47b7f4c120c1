// The HTML report (issues 8, 17): one static index.html per run, read in seconds: a summary (counts,
// run facts, what changed since the baselines, the command that approves every failure), the
// failures expanded with their images in a viewer (exposure on the float data, zoom, a magnifier on
// the worst block, heatmaps with a colour scale and an exceedance mask, the sphere under the
// pointer), the passing tests as a grid of thumbnails that open their card, and charts and history
// on their own tabs. It opens from the file system (file://), offline: CSS, JS and SVG charts are
// inline, every image it shows is copied next to it, and the float data is in data/*.js.
// The input is the results JSON the harness writes (results/RESULTS_FORMAT.md) and, optionally,
// the history file (JSON lines, one compact entry per run) for the trend sparklines.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "results/results_file.h"

namespace iblcheck::report {

// Writes out_dir/index.html (creating out_dir). Image paths in `results` are relative to
// `results_dir` (the folder that holds results.json); the images are copied to the same relative
// paths under out_dir (kept in place when out_dir is results_dir), so out_dir is self-contained.
// A missing image file is shown as a placeholder, not an error. `history`: entries as returned by
// read_history (oldest first); the current run is added to the trend unless it is already the
// last entry. Throws InputError naming results_dir/results.json and the problem when `results`
// does not follow the schema; Error when out_dir cannot be written.
// `findings`: explain/explore JSON files for the findings at the top (nightly_findings.h).
void write_report(const nlohmann::json& results, const std::filesystem::path& results_dir, const std::filesystem::path& out_dir,
                  const std::vector<nlohmann::json>& history = {}, const std::vector<nlohmann::json>& findings = {});

// read_results, validate_results: results/results_file.h.
using results::read_results;
using results::validate_results;

// History: JSON lines, one entry per run, oldest first. A missing file gives an empty history;
// a malformed line throws InputError naming file and line.
std::vector<nlohmann::json> read_history(const std::filesystem::path& file);

// The compact line a run appends:
// {"commit","dirty","date","suite","tests":{NAME:{"verdict","flip_mean","flip_noise","spirv_ipp","frame_ms",
//   "frame_ms_lo","frame_ms_hi","frame_n","precompute_ms","flicker"}}}
// flip_mean is accuracy vs the reference golden and flip_noise its noise floor (drift.h);
// frame_ms the median of the repeated timings, frame_ms_lo/hi their range; spirv_ipp the
// deterministic cost. Numbers absent from the results are left out.
nlohmann::json history_entry(const nlohmann::json& results);

// Appends `entry` as one line (creating the file and its folder) after read_history has validated
// the file (InputError naming file and line: nothing is written), under a lock, in one write.
// Returns the history with the entry.
std::vector<nlohmann::json> append_history(const std::filesystem::path& file, const nlohmann::json& entry);

} // namespace iblcheck::report

namespace iblcheck {
using report::append_history;
using report::history_entry;
using report::read_history;
using report::read_results;
using report::write_report;
} // namespace iblcheck
