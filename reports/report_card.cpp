// A test's card and its tile in the grid of passing tests (report_html.h); the image viewer each
// comparison shows is report_viewer.cpp.
#include <algorithm>
#include <cmath>
#include <iterator>
#include <tuple>

#include <fmt/format.h>

#include "metrics/catalog.h"
#include "reports/report_html.h"
#include "reports/verdict_text.h"

namespace iblcheck::report::html {

namespace {

// The exceedance mask's default threshold: the per-pixel tolerance of the comparison (p99: at
// most 1 % of the pixels may exceed it), else the block tolerance, else the mean's.
std::pair<double, std::string> mask_threshold(const json& cmp, const json& t) {
    auto from = [](const json& checks) -> std::optional<std::pair<double, std::string>> {
        if (!checks.is_array()) return std::nullopt;
        for (const char* m : {"flip.p99", "flip.block_max", "flip.mean"})
            for (const json& k : checks)
                if (str(k, "metric") == m)
                    if (auto mx = num(k, "max"))
                        return std::pair{*mx, fmt::format("{} must stay at or under {}", m, fmt_num(*mx))};
        return std::nullopt;
    };
    if (auto r = from(sub(cmp, "checks"))) return *r;
    // A reference comparison has no per-pixel tolerance: the test's baseline p99 tolerance, if any.
    if (sub(t, "comparisons").is_array())
        for (const json& c : t["comparisons"])
            if (str(c, "kind") == "baseline")
                if (auto r = from(sub(c, "checks")))
                    return {r->first, "no per-pixel tolerance against the truth; " + r->second + " against the baseline"};
    return {0.05, "no per-pixel tolerance: 0.05 shown"};
}

void comparison_html(std::string& o, const json& t, const json& cmp, size_t k, bool shown, PageContext& ctx) {
    auto out = std::back_inserter(o);
    const std::string kind = str(cmp, "kind"), cv = str(cmp, "verdict");
    fmt::format_to(out, "<div class=\"cmp\" data-cmp=\"{}\"{}>", k, shown ? "" : " hidden");
    const json& imgs = sub(cmp, "images");
    const bool identical = !str(imgs, "test_exr").empty() && str(imgs, "test_exr") == str(imgs, "golden_exr");
    fmt::format_to(out, "<div class=\"cmp-head\">{} against <span class=\"mono\">{}</span>{}{}</div>\n",
                   kind == "reference" ? "Accuracy: the render" : "The render", e(str(cmp, "golden")),
                   str(cmp, "label").empty() ? "" : " (label " + e(str(cmp, "label")) + ")",
                   identical ? ": <b>bit-identical</b> (FLIP 0 everywhere)" : "");
    ViewerSpec vs;
    vs.test_png = str(imgs, "test");
    vs.golden_png = str(imgs, "golden");
    vs.heat_png = str(imgs, "heatmap");
    vs.test_exr = str(imgs, "test_exr");
    vs.golden_exr = str(imgs, "golden_exr");
    vs.error_exr = str(imgs, "error_exr");
    vs.golden_name = kind == "reference" ? "truth" : "baseline";
    const json& wb = sub(cmp, "worst_block");
    const json& fl = sub(sub(cmp, "metrics"), "flip");
    auto bx = num(wb, "x") ? num(wb, "x") : num(fl, "block_x");
    auto by = num(wb, "y") ? num(wb, "y") : num(fl, "block_y");
    if (bx && by && (cv != "pass" || kind == "reference")) {
        vs.block_x = int(*bx);
        vs.block_y = int(*by);
        vs.block_sphere = str(wb, "sphere");
    }
    std::tie(vs.tol, vs.tol_note) = mask_threshold(cmp, t);
    if (!vs.test_png.empty() || !vs.golden_png.empty()) viewer_html(o, ctx, t, vs);
    // The tolerance table and every metric, folded.
    const json& checks = sub(cmp, "checks");
    const json& noise = sub(sub(t, "stability"), "noise_floor");
    const json& margins = sub(sub(t, "stability"), "margins");
    o += "<div class=\"cols\">";
    if (checks.is_array() && !checks.empty()) {
        const bool stab = noise.is_object() || margins.is_object();
        fmt::format_to(out,
                       "<table class=\"grid checks\"><tr><th>check</th><th>value</th><th>approved</th><th>min</th>"
                       "<th>max</th>{}<th>status</th></tr>",
                       stab ? "<th>noise floor</th><th>margin</th>" : "");
        for (const json& ck : checks) {
            const std::string m = str(ck, "metric"), st = str(ck, "status");
            auto cell = [&](const char* key) {
                auto v = num(ck, key);
                return v ? fmt_num(*v) : std::string("&ndash;");
            };
            std::string stab_cells;
            if (stab) {
                auto nf = num(noise, m.c_str());
                auto mg = num(margins, m.c_str());
                stab_cells = fmt::format("<td class=\"num\">{}</td><td class=\"num\">{}</td>", nf ? fmt_num(*nf) : "&ndash;",
                                         mg ? fmt_num(*mg) + "&times;" : "&ndash;");
            }
            fmt::format_to(out,
                           "<tr><td class=\"mono\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td "
                           "class=\"num\">{}</td><td class=\"num\">{}</td>{}<td class=\"st-{}\">{}</td></tr>",
                           e(m), cell("value"), cell("approved"), cell("min"), cell("max"), stab_cells, e(st), e(st));
        }
        o += "</table>";
    }
    const json& metrics = sub(cmp, "metrics");
    if (metrics.is_object() && !metrics.empty()) {
        o += "<details class=\"more\"><summary>all metrics</summary><dl class=\"metrics\">";
        for (auto& [group, vals] : metrics.items()) {
            if (!vals.is_object()) continue;
            std::string line;
            for (auto& [key, v] : vals.items())
                line += fmt::format("{}{} {}", line.empty() ? "" : " &middot; ", e(key), e(value_text(v)));
            fmt::format_to(out, "<dt>{}</dt><dd>{}</dd>", e(group), line);
        }
        o += "</dl></details>";
    }
    o += "</div></div>\n";
}

// Cost: the gated figure (SPIR-V instructions per pixel: deterministic) first, then wall times
// (median and range of the repeated timings).
void cost_html(std::string& o, const json& t) {
    auto out = std::back_inserter(o);
    std::vector<std::string> parts;
    const json& cost = sub(t, "cost");
    std::optional<double> approved;
    if (sub(t, "comparisons").is_array())
        for (const json& c : t["comparisons"])
            if (str(c, "kind") == "cost" && sub(c, "checks").is_array())
                for (const json& k : c["checks"])
                    if (str(k, "metric") == "cost.spirv_instructions_per_pixel") approved = num(k, "approved");
    if (auto ipp = num(cost, "spirv_instructions_per_pixel"))
        parts.push_back(fmt::format("SPIR-V instructions/pixel <b>{}</b>{}", fmt_num(*ipp),
                                    approved && *approved != *ipp ? " (approved " + fmt_num(*approved) + ")" : ""));
    if (auto f = num(t, "texture_fetches_per_pixel"))
        parts.push_back(fmt::format("texture fetches/pixel <b>{}</b>", fmt_num(*f)));
    if (auto fr = num(t, "frame_ms")) {
        const json& s = sub(t, "frame_ms_samples");
        // With a timing group, the samples are the renders of every test matching it (timing_groups.h).
        const std::string group = str(t, "timing_group");
        if (s.is_array() && s.size() > 1 && s.front().is_number() && s.back().is_number())
            parts.push_back(fmt::format("frame <b>{} ms</b> (median of {}{}, range {}&ndash;{})", fmt_num(*fr), s.size(),
                                        group.empty() ? "" : " renders of <span class=\"mono\">" + e(group) + "</span>",
                                        fmt_num(s.front().get<double>()), fmt_num(s.back().get<double>())));
        else
            parts.push_back(fmt::format("frame <b>{} ms</b> (one timing)", fmt_num(*fr)));
    }
    if (auto pre = num(t, "precompute_ms")) parts.push_back(fmt::format("precompute {} ms", fmt_num(*pre)));
    if (parts.empty()) return;
    std::string joined;
    for (auto& p : parts) joined += (joined.empty() ? "" : " &middot; ") + p;
    fmt::format_to(out, "<div><h4>Cost</h4><div class=\"meta\">{}</div>", joined);
    const json& tim = sub(t, "timings");
    if (tim.is_array() && !tim.empty()) {
        o += "<details class=\"more\"><summary>passes</summary><table class=\"grid\"><tr><th>pass</th><th>ms</th>"
             "<th>where</th><th>stage</th></tr>";
        for (const json& p : tim)
            fmt::format_to(out, "<tr><td class=\"mono\">{}</td><td class=\"num\">{}</td><td>{}</td><td>{}</td></tr>",
                           e(str(p, "pass")), fmt_num(num(p, "ms").value_or(0)), p.value("gpu", false) ? "GPU" : "CPU",
                           p.value("precompute", false) ? "precompute" : "per frame");
        o += "</table></details>";
    }
    o += "</div>";
}

// The variant's white-furnace figure (harness/furnace_figure.h): its energy against the exact
// albedo per roughness, so a reader sees which variants are energy-faithful.
void furnace_html(std::string& o, const json& t) {
    const json& f = sub(t, "furnace");
    const json& rs = sub(f, "roughness");
    const json& es = sub(f, "relative_error");
    if (!rs.is_array() || !es.is_array() || rs.size() != es.size() || rs.empty()) return;
    std::string cells;
    for (size_t i = 0; i < rs.size(); ++i)
        if (rs[i].is_number() && es[i].is_number())
            cells += fmt::format("{}r = {}: {:+.1f} %", cells.empty() ? "" : ", ", fmt_num(rs[i].get<double>()),
                                 100 * es[i].get<double>());
    o += "<div class=\"meta furnace\">white furnace (energy against the exact albedo, F0 = 1): " + e(cells) + "</div>";
}

void accuracy_html(std::string& o, const json& t) {
    auto out = std::back_inserter(o);
    const json& acc = sub(t, "accuracy");
    const json& ps = sub(t, "per_sphere");
    const MetricInfo& flip = metric("flip.mean"); // its names in the summary and in the truth's sidecar
    if (!num(acc, flip.accuracy_name) && !(ps.is_array() && !ps.empty())) return;
    o += "<div><h4>Accuracy against the truth</h4>";
    if (auto f = num(acc, flip.accuracy_name)) {
        const auto noise = num(sub(acc, "noise_floor"), flip.truth_noise_name);
        fmt::format_to(out, "<div class=\"meta\">mean FLIP <b>{}</b>{}{}</div>", fmt_num(*f),
                       str(acc, "golden").empty() ? "" : " against <span class=\"mono\">" + e(str(acc, "golden")) + "</span>",
                       noise ? fmt::format(" (the truth's own seed noise: {})", fmt_num(*noise)) : "");
    }
    if (ps.is_array() && !ps.empty()) {
        std::map<double, std::map<int, std::vector<const json*>>> grid; // roughness -> metal? -> spheres
        for (const json& sp : ps)
            grid[num(sp, "roughness").value_or(0)][num(sp, "metallic").value_or(0) >= 0.5 ? 1 : 0].push_back(&sp);
        o += "<table class=\"grid spheres\"><tr><th>FLIP per sphere, roughness</th>";
        for (auto& [r, _] : grid) fmt::format_to(out, "<th class=\"num\">{}</th>", fmt_num(r));
        o += "</tr>";
        for (int metal : {1, 0}) {
            bool any = false;
            for (auto& [r, byclass] : grid) any = any || byclass.count(metal);
            if (!any) continue;
            fmt::format_to(out, "<tr><th>{}</th>", metal ? "metal" : "dielectric");
            for (auto& [r, byclass] : grid) {
                std::string cell, tip;
                if (auto it = byclass.find(metal); it != byclass.end())
                    for (const json* sp : it->second) {
                        cell += (cell.empty() ? "" : " / ") + fmt_num(num(*sp, "flip_mean").value_or(0));
                        tip += (tip.empty() ? "" : "; ") + str(*sp, "label");
                    }
                fmt::format_to(out, "<td class=\"num\" title=\"{}\">{}</td>", e(tip), cell.empty() ? "&ndash;" : cell);
            }
            o += "</tr>";
        }
        o += "</table>";
    }
    o += "</div>";
}

void temporal_html(std::string& o, const json& tp, ImageStore& store) {
    if (!tp.is_object()) return;
    auto out = std::back_inserter(o);
    constexpr size_t kStrip = 8;
    auto urls = [&](const char* key) {
        std::vector<std::string> u;
        const json& a = sub(tp, key);
        if (a.is_array())
            for (const json& f : a)
                if (f.is_string())
                    if (auto x = store.url(f.get<std::string>())) u.push_back(*x);
        return u;
    };
    std::vector<std::string> ft = urls("frames"), fr = urls("reference_frames");
    const json& a = sub(tp, "frames");
    o += "<div class=\"temporal\"><h4>Temporal stability</h4>";
    std::vector<std::string> parts;
    for (const char* k : {"flicker", "variation_ratio", "flip_mean"})
        if (auto v = num(tp, k)) parts.push_back(fmt::format("{} <b>{}</b>", k, fmt_num(*v)));
    // Against the temporal truth (the quadrature truth of every frame), when the golden store has it.
    const json& truth = sub(tp, "truth");
    for (const char* k : {"flicker", "flip_mean"})
        if (auto v = num(truth, k)) parts.push_back(fmt::format("truth {} <b>{}</b>", k, fmt_num(*v)));
    std::string joined;
    for (auto& p : parts) joined += (joined.empty() ? "" : " &middot; ") + p;
    fmt::format_to(out, "<div class=\"meta\">{} &middot; {} frames{}</div>", joined, a.is_array() ? a.size() : 0,
                   ft.size() < (a.is_array() ? a.size() : 0) ? " (some missing)" : "");
    auto strip = [&](const char* label, const std::vector<std::string>& u) {
        if (u.empty()) return;
        fmt::format_to(out, "<div class=\"strip\"><span class=\"lbl\">{}<br>frames 1&ndash;{}</span>", label,
                       std::min(u.size(), kStrip));
        for (size_t i = 0; i < u.size() && i < kStrip; ++i)
            fmt::format_to(out, "<img class=\"frame\" src=\"{}\" alt=\"{} frame {}\" title=\"{} frame {}\">", e(u[i]), label,
                           i + 1, label, i + 1);
        o += "</div>";
    };
    strip("test", ft);
    strip("reference", fr);
    if (!ft.empty() || !fr.empty()) {
        auto join = [](const std::vector<std::string>& v) {
            std::string s;
            for (auto& x : v) s += (s.empty() ? "" : " ") + x;
            return s;
        };
        fmt::format_to(out,
                       "<div class=\"player\" data-frames=\"{}\" data-ref-frames=\"{}\">{}{}"
                       "<button type=\"button\">&#9654; play</button><input type=\"range\" min=\"0\" max=\"0\" "
                       "value=\"0\" aria-label=\"frame\"><span class=\"fr meta\"></span></div>",
                       e(join(ft)), e(join(fr)),
                       ft.empty() ? ""
                                  : fmt::format("<figure><img class=\"pt\" src=\"{}\" alt=\"test\"><figcaption>test"
                                                "</figcaption></figure>",
                                                e(ft[0])),
                       fr.empty() ? ""
                                  : fmt::format("<figure><img class=\"pr\" src=\"{}\" alt=\"reference\">"
                                                "<figcaption>reference</figcaption></figure>",
                                                e(fr[0])));
    }
    o += "</div>";
}

std::string thumbnail_rel(const json& t) {
    if (!str(t, "image").empty()) return str(t, "image");
    if (sub(t, "comparisons").is_array())
        for (const json& c : t["comparisons"])
            if (!str(sub(c, "images"), "test").empty()) return str(sub(c, "images"), "test");
    return "";
}

// The card's facts (scene, environment, method, variant, size, tags) and its stability line.
void card_meta(std::string& o, const json& t) {
    auto out = std::back_inserter(o);
    std::vector<std::string> meta;
    for (const char* k : {"scene", "env", "method", "variant"})
        if (!str(t, k).empty()) meta.push_back(fmt::format("{} <b>{}</b>", k, e(str(t, k))));
    if (auto w = num(t, "width"), h = num(t, "height"); w && h) meta.push_back(fmt::format("{}&times;{} px", *w, *h));
    if (const json& tags = sub(t, "tags"); tags.is_array())
        for (const json& tag : tags)
            if (tag.is_string()) {
                std::string tg = tag.get<std::string>();
                meta.push_back(tg.rfind("failure:", 0) == 0 ? "failure mode <b>" + e(tg.substr(8)) + "</b>" : "tag " + e(tg));
            }
    std::string mj;
    for (auto& m : meta) mj += (mj.empty() ? "" : " &middot; ") + m;
    fmt::format_to(out, "<div class=\"meta\">{}</div>\n", mj);
    if (const json& st = sub(t, "stability"); st.is_object()) {
        std::string line = st.value("deterministic", false) ? "bit-identical across repeats and thread counts"
                                                            : "<b>not deterministic</b>: " + e(str(st, "nondeterminism"));
        for (auto& [k, val] : sub(st, "sensitivity").items())
            if (auto f = num(val, "flip.mean"))
                line += fmt::format(" &middot; {} {} moves FLIP by {}", e(k), e(value_text(sub(val, "value"))), fmt_num(*f));
        fmt::format_to(out, "<div class=\"meta\">stability: {}</div>\n", line);
    }
}

// Why the test did not pass: the platform warning, the lines `iblcheck run` prints, and the bless
// command that approves it.
void card_why(std::string& o, const json& t, const std::string& v) {
    auto out = std::back_inserter(o);
    if (!str(t, "driver_mismatch").empty())
        fmt::format_to(out,
                       "<div class=\"warn\">&#9888; {} &mdash; differences may come from the platform (driver or "
                       "the CPU llvmpipe generates code for), not the shader.</div>\n",
                       e(str(t, "driver_mismatch")));
    // What failed, where, by how much, and the accuracy against the truth before -> after: the
    // lines `iblcheck run` prints (verdict_text.h).
    std::vector<std::string> why = verdict_details(t);
    // Its last line, the bless command, is shown below as a command to copy.
    if (!why.empty() && (why.back().rfind("approve: ", 0) == 0 || why.back().rfind("lock it in: ", 0) == 0)) why.pop_back();
    if (!why.empty()) {
        o += "<ul class=\"why\">";
        for (const std::string& line : why)
            fmt::format_to(out, "<li{}>{}</li>", line.rfind("accuracy vs truth", 0) == 0 ? " class=\"acc\"" : "", e(line));
        o += "</ul>\n";
    } else if (v != "pass" && !str(t, "message").empty()) {
        fmt::format_to(out, "<ul class=\"why\"><li>{}</li></ul>\n", e(str(t, "message")));
    }
    if (needs_bless(v) && !str(t, "bless_command").empty())
        fmt::format_to(out,
                       "<div class=\"cmd bless\"><span class=\"lbl\">{}</span><pre><code>{}</code></pre><button "
                       "type=\"button\" class=\"copy\">Copy</button></div>\n",
                       v == "missing-golden" ? "no golden yet; make this image the golden:"
                       : v == "improved"     ? "closer to the truth than the golden; accept it:"
                                             : "if the change is intended, approve it:",
                       e(str(t, "bless_command")));
}

// The image comparisons, one shown at a time, or the rendering alone when nothing was compared.
void card_images(std::string& o, const json& t, const std::string& name, const std::string& v, PageContext& ctx) {
    auto out = std::back_inserter(o);
    // Image comparisons, one shown at a time: the first that did not pass, else the baseline.
    std::vector<const json*> cmps;
    if (sub(t, "comparisons").is_array())
        for (const json& c : t["comparisons"])
            if (str(c, "kind") != "cost") cmps.push_back(&c);
    // Shown first: the first comparison that did not pass; when all passed, the truth (a passing
    // render is usually bit-identical to its baseline: nothing to see there).
    size_t first = cmps.size();
    for (size_t k = 0; k < cmps.size() && first == cmps.size(); ++k)
        if (str(*cmps[k], "verdict") != "pass") first = k;
    for (size_t k = 0; k < cmps.size() && first == cmps.size(); ++k)
        if (str(*cmps[k], "kind") == "reference") first = k;
    if (first == cmps.size()) first = 0;
    if (cmps.size() > 1) {
        o += "<div class=\"cmp-tabs\"><span class=\"meta\">compare with</span>";
        for (size_t k = 0; k < cmps.size(); ++k) {
            const std::string kind = str(*cmps[k], "kind"), cv = str(*cmps[k], "verdict");
            fmt::format_to(out, "<button type=\"button\" data-cmp=\"{}\"{}>{} <span class=\"badge v-{}\">{}</span></button>", k,
                           k == first ? " class=\"on\"" : "", kind == "reference" ? "the truth (reference)" : "the " + e(kind),
                           e(cv), e(cv));
        }
        o += "</div>\n";
    }
    for (size_t k = 0; k < cmps.size(); ++k) comparison_html(o, t, *cmps[k], k, k == first, ctx);
    // Nothing compared (missing golden, error): the rendering alone, still with its exposure control.
    bool shown = false;
    for (const json* c : cmps) shown = shown || !str(sub(*c, "images"), "test").empty();
    if (!shown) {
        std::string rel = str(t, "image");
        if (rel.empty() && !name.empty() && name.find('/') == std::string::npos && name != "." && name != "..")
            if (ctx.images.exists("images/" + name + "/test.png")) rel = "images/" + name + "/test.png";
        if (!rel.empty()) {
            ViewerSpec vs;
            vs.test_png = rel;
            vs.test_exr = str(t, "image_exr");
            viewer_html(o, ctx, t, vs);
            if (v == "missing-golden") o += "<div class=\"meta\">no golden to compare with yet</div>";
        }
    }
}

// The test's history in one line: its verdicts and what moved.
void card_trend(std::string& o, const Trend& trend) {
    if (!trend.any) return;
    std::string moved;
    if (!trend.flip.moved.empty())
        moved += " &middot; <span class=\"moved-txt\">accuracy moved " + e(trend.flip.moved) + "</span>";
    if (!trend.cost.moved.empty()) moved += " &middot; <span class=\"moved-txt\">cost moved " + e(trend.cost.moved) + "</span>";
    if (!trend.frame.moved.empty())
        moved += " &middot; <span class=\"moved-txt\">frame time moved " + e(trend.frame.moved) + "</span>";
    fmt::format_to(
        std::back_inserter(o),
        "<div class=\"trend\">History: <span class=\"vstrip\">{}</span>{} &middot; <a href=\"#history\">trend</a></div>",
        trend.verdict_strip, moved);
}

} // namespace

void test_card(std::string& o, const json& t, size_t idx, PageContext& ctx, const Trend& trend, bool expanded) {
    auto out = std::back_inserter(o);
    const std::string name = str(t, "name"), v = str(t, "verdict");
    fmt::format_to(out, "<section class=\"test s-{0} {3}\" id=\"{1}\" data-name=\"{2}\" data-verdict=\"{0}\"{4}>\n", e(v),
                   test_id(idx), e(name), expanded ? "filterable" : "folded", expanded ? "" : " hidden");
    const bool flaky = sub(t, "stability").is_object() && sub(t, "stability").value("flaky", false);
    fmt::format_to(out,
                   "<div class=\"thead\"><span class=\"badge v-{0}\">{0}</span> <h3><a href=\"#{1}\">{2}</a></h3>{3}{4}</div>\n",
                   e(v), test_id(idx), e(name), flaky ? " <span class=\"badge flaky\">flaky</span>" : "",
                   expanded ? "" : "<button type=\"button\" class=\"fold\" title=\"fold this card\">fold &#9650;</button>");
    card_meta(o, t);
    card_why(o, t, v);
    card_images(o, t, name, v, ctx);
    o += "<div class=\"cols\">";
    cost_html(o, t);
    accuracy_html(o, t);
    furnace_html(o, t);
    o += "</div>";
    temporal_html(o, sub(t, "temporal"), ctx.images);
    card_trend(o, trend);
    o += "</section>\n";
}

void test_tile(std::string& o, const json& t, size_t idx, PageContext& ctx) {
    auto out = std::back_inserter(o);
    const std::string name = str(t, "name"), v = str(t, "verdict");
    const std::string rel = thumbnail_rel(t);
    std::string thumb = "<div class=\"noimg\">no image</div>";
    // The render at its automatic exposure when its EXR is there, else the PNG (exposure 0).
    std::string exr = str(t, "image_exr");
    if (auto th = ctx.data.thumbnail(exr, 280, 64))
        thumb = fmt::format("<img class=\"thumb\" src=\"{}\" alt=\"\" title=\"automatic exposure\">", e(*th));
    else if (!rel.empty()) {
        if (auto u = ctx.images.url(rel))
            thumb = fmt::format("<img class=\"thumb\" src=\"{}\" alt=\"\">", e(*u));
        else
            thumb = fmt::format("<div class=\"noimg\">missing image: {}</div>", e(rel));
    }
    std::vector<std::string> nums;
    if (auto a = num(sub(t, "accuracy"), "flip_mean")) nums.push_back("truth " + fmt_num(*a));
    if (auto c = num(sub(t, "cost"), "spirv_instructions_per_pixel")) nums.push_back(fmt_num(*c) + " instr/px");
    std::string nj;
    for (auto& n : nums) nj += (nj.empty() ? "" : " &middot; ") + n;
    fmt::format_to(out,
                   "<div class=\"tile s-{0} filterable\" data-name=\"{1}\" data-verdict=\"{0}\" data-card=\"{2}\" "
                   "tabindex=\"0\" role=\"button\" title=\"{1}: open\">{3}<div class=\"tl1\">{4}</div><div class=\"tl2\">"
                   "{5} &middot; {6}</div></div>\n",
                   e(v), e(name), test_id(idx), thumb, e(test_label(t)), e(str(t, "scene") + " \u00b7 " + str(t, "env")), nj);
}

} // namespace iblcheck::report::html
