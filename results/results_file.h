// The results file (schema iblcheck-results/1, results/RESULTS_FORMAT.md): what a run writes and the
// report, the history and `iblcheck report` read.
#pragma once
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

namespace iblcheck::results {

// Reads and validates a results file (InputError naming the file: unreadable, not JSON, schema).
nlohmann::json read_results(const std::filesystem::path& results_file);

// Checks `results` against schema iblcheck-results/1; throws InputError "<source>: <where>: <problem>".
void validate_results(const nlohmann::json& results, const std::string& source);

} // namespace iblcheck::results
