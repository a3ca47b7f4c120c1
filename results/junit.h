// JUnit XML for CI dashboards: one testcase per test; fail and missing-golden are <failure>
// (with the bless command), error is <error>, improved is noted in <system-out>.
#pragma once
#include <filesystem>

#include <nlohmann/json.hpp>

namespace iblcheck {

void write_junit(const nlohmann::json& results, const std::filesystem::path& file);

} // namespace iblcheck
