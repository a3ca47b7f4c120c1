#include "junit.h"

#include <fmt/core.h>

#include "kernel/atomic_file.h"
#include "kernel/errors.h"
#include "kernel/markup.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace iblcheck {

void write_junit(const json& results, const fs::path& file) {
    const json& tests = results.at("tests");
    int failures = 0, errors = 0;
    for (auto& t : tests) {
        std::string v = t.value("verdict", "error");
        failures += v == "fail" || v == "missing-golden";
        errors += v == "error";
    }
    std::string suite = results.value("suite", "iblcheck");
    std::string x = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
    x += fmt::format("<testsuites name=\"iblcheck\" tests=\"{}\" failures=\"{}\" errors=\"{}\" time=\"{:.3f}\">\n", tests.size(),
                     failures, errors, results.value("total_s", 0.0));
    x += fmt::format(
        "  <testsuite name=\"{}\" tests=\"{}\" failures=\"{}\" errors=\"{}\" skipped=\"0\" time=\"{:.3f}\" timestamp=\"{}\">\n",
        escape_markup(suite), tests.size(), failures, errors, results.value("total_s", 0.0),
        escape_markup(results.value("started", "")));
    for (auto& t : tests) {
        std::string name = t.value("name", "?"), v = t.value("verdict", "error"), msg = t.value("message", "");
        x += fmt::format("    <testcase classname=\"{}.{}\" name=\"{}\" time=\"{:.3f}\">", escape_markup(suite),
                         escape_markup(t.value("method", "")), escape_markup(name), t.value("wall_s", 0.0));
        if (v == "fail" || v == "missing-golden")
            x += fmt::format("\n      <failure type=\"{}\" message=\"{}\">{}\nrebless: {}</failure>\n    ", v, escape_markup(msg),
                             escape_markup(msg), escape_markup(t.value("bless_command", "")));
        else if (v == "error")
            x += fmt::format("\n      <error type=\"error\" message=\"{}\">{}</error>\n    ", escape_markup(msg),
                             escape_markup(msg));
        else if (v == "improved")
            x += fmt::format("\n      <system-out>improved: {}</system-out>\n    ", escape_markup(msg));
        x += "</testcase>\n";
    }
    x += "  </testsuite>\n</testsuites>\n";
    if (!file.parent_path().empty()) fs::create_directories(file.parent_path());
    write_file_atomically(file, x, "JUnit XML"); // a CI reading it mid-write sees the old file or the new, never half
}

} // namespace iblcheck
