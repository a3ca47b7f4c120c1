// `iblcheck doctor`: what Vulkan driver the harness will use and whether it has what we need.
#include <fmt/core.h>
#include <fmt/ranges.h>

#include "commands.h"
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include "cli/store_folders.h"
#include "harness/golden_store.h"
#include "harness/provenance.h"
#include "kernel/cpu_caps.h"
#include "kernel/errors.h"
#include "kernel/program.h"
#include "renderers/vulkan/context.h"
#include "renderers/vulkan/fp16_emulation.h"

namespace iblcheck::cli {

namespace {
// For each committed golden set (the primary baselines, and each @label), the platforms its
// goldens were blessed on, and whether this machine is one of them: a different platform means
// renders may differ within the cross-CPU noise floor (the verdict still comes from tolerances).
void print_golden_sets(const std::string& driver_info) {
    namespace fs = std::filesystem;
    GoldenStore store;
    fs::path dir = store.root() / "baseline";
    if (!fs::is_directory(dir)) {
        fmt::print("golden sets:     none in {}\n", dir.string());
        return;
    }
    struct Set {
        int count = 0;
        std::set<std::string> platforms;
    };
    std::map<std::string, Set> sets;
    for (auto& e : fs::directory_iterator(dir)) {
        if (e.path().extension() != ".json" || !e.is_regular_file()) continue; // a FIFO would block
        std::ifstream f(e.path());
        auto p = nlohmann::json::parse(f, nullptr, false);
        if (!p.is_object()) continue;
        std::string label = p.value("label", std::string());
        Set& s = sets[label.empty() ? "primary" : "@" + label];
        ++s.count;
        s.platforms.insert(p.value("driver", nlohmann::json::object()).value("driver_info", std::string("?")) + " | CPU class " +
                           p.value("cpu_class", std::string("unrecorded")));
    }
    const std::string here = driver_info + " | CPU class " + this_cpu_class();
    fmt::print("golden sets ({}):\n", dir.string());
    for (auto& [name, s] : sets) {
        bool match = s.platforms.count(here) > 0;
        fmt::print("  {:<16} {:>4} goldens, blessed on {}: {}\n", name, s.count, fmt::join(s.platforms, "; "),
                   match ? "matches this machine" : "differs from this machine (" + here + ")");
    }
}
} // namespace

void register_doctor_command(CLI::App& app, int& exit_code) {
    auto* cmd = app.add_subcommand("doctor", "Print the Vulkan driver, its versions and the features iblcheck uses");
    static std::string device;
    static bool validation = false;
    cmd->add_option("--device", device, "Substring of the device/driver name (default: lavapipe)");
    cmd->add_flag("--validation", validation, "Also check that the Khronos validation layer loads");
    cmd->callback([&exit_code] {
        vk::ContextOptions opt;
        opt.device = device;
        opt.validation = validation;
        vk::Context ctx(opt); // throws EnvironmentError with a one-line fix when there is no driver
        const auto& i = ctx.info();
        fmt::print("device:          {} ({})\n", i.device_name, i.device_type);
        fmt::print("driver:          {}\n", i.driver_name);
        fmt::print("driver info:     {}\n", i.driver_info);
        fmt::print("mesa version:    {}\n", i.mesa_version.empty() ? "n/a" : i.mesa_version);
        fmt::print("llvm version:    {}\n", i.llvm_version.empty() ? "n/a" : i.llvm_version);
        fmt::print("vulkan api:      {}\n", i.api_version);
        fmt::print("shaderFloat16:   {}\n", i.shader_float16 ? "yes" : "no");
        // The renderer's own rule (fp16=auto), so this line cannot disagree with what a render does.
        fmt::print("precision=mediump: {}\n",
                   vk::fp16_path_description(vk::choose_fp16_path("auto", i.shader_float16, i.device_name)));
        fmt::print("16-bit storage:  {}\n", i.storage_16bit ? "yes" : "no");
        fmt::print("timestamps:      {} (period {} ns)\n", i.timestamps ? "yes" : "no", i.timestamp_period_ns);
        fmt::print("validation:      {}\n", i.validation ? "on" : "off");
        fmt::print("shader folder:   {}\n", vk::shader_dir().string());
        // The precompute and cost stores' code key (program.h): what a rebuild keeps or misses.
        fmt::print("store code key:  {}\n", render_code_hash());
        fmt::print("metrics code key: {}\n", metrics_code_hash()); // the metrics store's (program.h)
        // How full the stores are against their budget (store_budget.h); the oldest go after a run that writes.
        const StoreUsage use = store_usage(store_folders());
        fmt::print(
            "stores:          {} entries, {:.0f} MiB of a {} MiB budget (IBLCHECK_CACHE_MAX_MB; least recently used go first)\n",
            use.entries, double(use.bytes) / (1 << 20), store_budget_bytes() >> 20);
        // What llvmpipe generates shader code for (lavapipe compiles for the host CPU); meaningful
        // when the driver is llvmpipe.
        LlvmpipeCaps caps = llvmpipe_caps();
        auto yn = [](bool b) { return b ? "yes" : "no"; };
        fmt::print("llvmpipe cpu:    {} (vector width {} bits; F16C {}, FMA {}, AVX2 {}, AVX-512 {})\n", caps.cpu_class(),
                   caps.vector_width, yn(caps.f16c), yn(caps.fma), yn(caps.avx2), yn(caps.avx512));
        if (!caps.override_caps.empty()) fmt::print("cpu override:    GALLIUM_OVERRIDE_CPU_CAPS={}\n", caps.override_caps);
        if (!caps.warning.empty()) fmt::print(stderr, "warning: {}\n", caps.warning);
        print_golden_sets(i.driver_info);
        fmt::print("all devices:\n");
        for (const auto& d : i.available_devices) fmt::print("  {}\n", d);
        exit_code = i.timestamps ? kExitPass : kExitError;
        if (!i.timestamps) fmt::print(stderr, "error: {}: no timestamp queries; per-pass timings need them\n", i.device_name);
    });
}

} // namespace iblcheck::cli
