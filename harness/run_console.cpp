#include "run_console.h"

#include <fmt/core.h>

#include <cstdio>
#include <set>

#include "reports/verdict_text.h"

using nlohmann::json;

namespace iblcheck {

void print_test_line(const json& r, int n, size_t total, bool interactive) {
    std::string acc = r["accuracy"].is_object() ? fmt::format("  vs truth {:.4f}", r["accuracy"]["flip_mean"].get<double>()) : "";
    const std::string v = r["verdict"].get<std::string>();
    fmt::print("{}[{:>3}/{}] {:<15} {}{}  ({:.1f} s)\n", interactive ? "\r" : "", n, total, v, r["name"].get<std::string>(), acc,
               r["wall_s"].get<double>());
    for (const std::string& line : verdict_details(r)) fmt::print("          {}\n", line);
    std::fflush(stdout);
}

void print_run_summary(const json& R, const RunSummary& s, size_t n_tests, const RunOptions& o, const std::string& suite_arg,
                       const std::string& shader_arg) {
    // The fp16 path mediump tests took (doctor states the same rule): native float16_t, or the
    // emulation on a driver without shaderFloat16 (e.g. a CPU without F16C).
    std::set<std::string> fp16;
    for (const json& r : R["tests"])
        if (r.contains("provenance") && r["provenance"].contains("fp16")) fp16.insert(r["provenance"]["fp16"].get<std::string>());
    for (const std::string& f : fp16)
        fmt::print("precision=mediump ran with {} fp16{}\n", f,
                   f == "emulated" ? " (no shaderFloat16: fp32 rounded to fp16 after every fp16 operation)" : " (float16_t)");
    fmt::print("{} tests: {} pass, {} fail, {} improved, {} missing-golden, {} error  ({:.1f} s){}\n", n_tests, s.pass, s.fail,
               s.improved, s.missing, s.error, R["total_s"].get<double>(),
               o.out_dir.empty() ? "" : "  report: " + (o.out_dir / "index.html").string());
    if (std::string all = rebless_all_line(R["tests"], suite_arg, shader_arg); !all.empty()) fmt::print("{}\n", all);
}

} // namespace iblcheck
