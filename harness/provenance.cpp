#include "provenance.h"

#include "golden_store.h"
#include "kernel/cpu_caps.h"

using nlohmann::json;

namespace iblcheck {

std::string this_cpu_class() { return llvmpipe_caps().cpu_class(); }

json run_provenance() {
    bool dirty = false;
    std::string commit = project_commit(&dirty);
    return {{"commit", commit + (dirty ? "-dirty" : "")},
            {"date", utc_now_iso()},
            {"cpu_features", cpu_features()},
            {"cpu_class", this_cpu_class()}};
}

json render_cost(const RenderResult& r) {
    json c = r.provenance.value("cost", json::object());
    if (!c.contains("texture_fetches_per_pixel") && r.texture_fetches_per_pixel > 0)
        c["texture_fetches_per_pixel"] = r.texture_fetches_per_pixel;
    return c;
}

std::string platform_difference(const json& golden, const json& render, const std::string& cpu_class) {
    auto driver = [](const json& p) { return p.value("driver", json::object()).value("driver_info", std::string()); };
    const std::string gd = driver(golden), rd = driver(render);
    const std::string gc = golden.value("cpu_class", std::string());
    std::string diff;
    if (!gd.empty() && !rd.empty() && gd != rd) diff += "driver " + gd + " -> " + rd;
    if (!gc.empty() && gc != cpu_class) diff += (diff.empty() ? "" : ", ") + ("CPU class " + gc + " -> " + cpu_class);
    return diff.empty() ? "" : "golden blessed on another platform: " + diff;
}

json baseline_facts(const json& golden) {
    json out = json::object();
    for (const char* k : {"commit", "date", "shader_tree_hash", "cpu_class", "label"})
        if (golden.contains(k) && golden[k].is_string()) out[k] = golden[k];
    if (golden.contains("shader_files") && golden["shader_files"].is_object()) out["shader_files"] = golden["shader_files"];
    const json driver = golden.value("driver", json::object());
    if (driver.is_object() && driver.contains("driver_info") && driver["driver_info"].is_string())
        out["driver_info"] = driver["driver_info"];
    return out;
}

} // namespace iblcheck
