// The static HTML report (issue 8). See report_writer.h and reports/RESULTS_FORMAT.md.
#include "reports/report_writer.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <iterator>
#include <map>
#include <optional>
#include <set>

#include <fmt/format.h>

#include "harness/common/errors.h"
#include "reports/report_assets.h"
#include "reports/svg_chart.h"

namespace iblcheck::report {

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

// ---- lenient accessors (the results are validated before rendering) ----
std::string str(const json& j, const char* k) {
    auto it = j.find(k);
    if (it == j.end() || !it->is_string()) return "";
    return it->get<std::string>();
}
std::optional<double> num(const json& j, const char* k) {
    if (!j.is_object()) return std::nullopt;
    auto it = j.find(k);
    if (it == j.end() || !it->is_number()) return std::nullopt;
    return it->get<double>();
}
const json& sub(const json& j, const char* k) {
    static const json null_json;
    if (!j.is_object()) return null_json;
    auto it = j.find(k);
    return it == j.end() ? null_json : *it;
}
std::string e(std::string_view s) { return html_escape(s); }
std::string value_text(const json& v) {
    if (v.is_string()) return v.get<std::string>();
    if (v.is_number()) return fmt_num(v.get<double>());
    if (v.is_null()) return "";
    return v.dump();
}

const std::vector<std::string> kVerdictOrder{"fail", "error", "missing-golden", "improved", "pass"};
int verdict_rank(const std::string& v) {
    auto it = std::find(kVerdictOrder.begin(), kVerdictOrder.end(), v);
    return int(it - kVerdictOrder.begin());
}
bool needs_bless(const std::string& v) { return v == "fail" || v == "missing-golden" || v == "improved"; }

std::string method_color(const std::string& m) {
    if (m == "mobile") return "#e8590c";
    if (m == "sampled") return "#1c7ed6";
    if (m == "reference") return "#2f9e44";
    static const char* pal[] = {"#ae3ec9", "#f59f00", "#0ca678", "#d6336c", "#495057", "#3b5bdb"};
    size_t h = std::hash<std::string>{}(m);
    return pal[h % 6];
}
const char* kPalette[] = {"#e8590c", "#1c7ed6", "#2f9e44", "#ae3ec9", "#f59f00", "#0ca678",
                          "#d6336c", "#3b5bdb", "#795548", "#495057", "#15aabf", "#82c91e"};

// ---- images: copy what the report shows so that out_dir is self-contained ----
std::string url_encode_path(const std::string& p) {
    std::string o;
    for (unsigned char c : p) {
        if (std::isalnum(c) || c == '-' || c == '.' || c == '_' || c == '~' || c == '/')
            o += char(c);
        else
            o += fmt::format("%{:02X}", c);
    }
    return o;
}

class ImageStore {
  public:
    ImageStore(fs::path results_dir, fs::path out_dir) : results_dir_(std::move(results_dir)), out_dir_(std::move(out_dir)) {}

    // URL (relative to index.html) of the image, or nullopt when the file is missing.
    std::optional<std::string> url(const std::string& rel) {
        if (rel.empty()) return std::nullopt;
        if (auto it = done_.find(rel); it != done_.end()) return it->second;
        std::optional<std::string> result;
        fs::path p(rel);
        fs::path src = p.is_absolute() ? p : results_dir_ / p;
        std::error_code ec;
        if (!fs::is_regular_file(src, ec)) {
            missing_.push_back(rel);
        } else {
            bool clean = !p.is_absolute() && !p.empty();
            for (const auto& part : p)
                if (part == ".." || part == ".") clean = false;
            fs::path dest_rel = clean ? p : fs::path("images/_external") /
                                                (std::to_string(++external_) + "_" + p.filename().string());
            fs::path dest = out_dir_ / dest_rel;
            if (!(fs::exists(dest, ec) && fs::equivalent(src, dest, ec))) {
                fs::create_directories(dest.parent_path(), ec);
                if (!fs::copy_file(src, dest, fs::copy_options::overwrite_existing, ec))
                    throw Error(fmt::format("{}: cannot copy image into the report: {}", dest.string(), ec.message()));
            }
            result = url_encode_path(dest_rel.generic_string());
        }
        done_[rel] = result;
        return result;
    }
    const std::vector<std::string>& missing() const { return missing_; }
    bool exists(const std::string& rel) const {
        std::error_code ec;
        return fs::is_regular_file(results_dir_ / rel, ec);
    }

  private:
    fs::path results_dir_, out_dir_;
    std::map<std::string, std::optional<std::string>> done_;
    std::vector<std::string> missing_;
    int external_ = 0;
};

// ---- history ----
struct History {
    std::vector<const json*> runs; // oldest first, at most kMaxRuns, current run last
    static constexpr size_t kMaxRuns = 30;
};

std::vector<SparkRun> series_for(const History& h, const std::string& test, const char* key) {
    std::vector<SparkRun> out;
    for (const json* r : h.runs) {
        SparkRun s;
        s.commit = str(*r, "commit");
        if (r->value("dirty", false)) s.commit += "+dirty";
        s.date = str(*r, "date");
        s.value = num(sub(sub(*r, "tests"), test.c_str()), key);
        out.push_back(std::move(s));
    }
    return out;
}

struct Trend {
    Sparkline flip, frame;
    std::string verdict_strip;
    bool any = false;
};

Trend trend_for(const History& h, const std::string& test) {
    Trend t;
    if (h.runs.size() < 2) return t;
    t.flip = render_sparkline("history-flip_mean", test, series_for(h, test, "flip_mean"), 0.10, 1e-4, "");
    t.frame = render_sparkline("history-frame_ms", test, series_for(h, test, "frame_ms"), 0.10, 0.05, " ms");
    for (const json* r : h.runs) {
        const std::string v = str(sub(sub(*r, "tests"), test.c_str()), "verdict");
        t.verdict_strip += fmt::format("<span class=\"v-{}\" title=\"{} {}: {}\"></span>",
                                       v.empty() ? "none" : e(v), e(str(*r, "commit")), e(str(*r, "date")),
                                       v.empty() ? "not run" : e(v));
    }
    t.any = t.flip.points + t.frame.points > 0;
    return t;
}

// ---- HTML pieces ----
std::string img_or_missing(ImageStore& store, const std::string& rel, const char* cls, const std::string& alt) {
    if (rel.empty()) return "";
    if (auto u = store.url(rel))
        return fmt::format("<img class=\"{}\" src=\"{}\" alt=\"{}\">", cls, e(*u), e(alt));
    return fmt::format("<div class=\"noimg\">missing image:<br><span class=\"mono\">{}</span></div>", e(rel));
}

void comparison_html(std::string& o, const json& t, const json& cmp, ImageStore& store) {
    auto out = std::back_inserter(o);
    const std::string kind = str(cmp, "kind"), cv = str(cmp, "verdict");
    fmt::format_to(out, "<h4>{} comparison{}{}{}</h4>\n", e(kind) + (str(cmp, "label").empty() ? "" : " (" + e(str(cmp, "label")) + ")"),
                   cmp.contains("golden") ? " against <span class=\"mono\">" + e(str(cmp, "golden")) + "</span>" : "",
                   cv.empty() ? "" : fmt::format(" <span class=\"badge v-{}\">{}</span>", e(cv), e(cv)), "");
    if (!str(cmp, "message").empty()) fmt::format_to(out, "<div class=\"message\">{}</div>\n", e(str(cmp, "message")));
    const json& imgs = sub(cmp, "images");
    const std::string ti = str(imgs, "test"), gi = str(imgs, "golden"), hi = str(imgs, "heatmap");
    if (!ti.empty() || !gi.empty() || !hi.empty()) {
        o += "<div class=\"images\">";
        if (!ti.empty()) {
            auto tu = store.url(ti);
            auto gu = gi.empty() ? std::nullopt : store.url(gi);
            if (tu && gu)
                fmt::format_to(out,
                               "<figure><div class=\"flick\" title=\"hover: show the golden in place (flicker "
                               "comparison)\"><img class=\"t\" src=\"{}\" alt=\"test\"><img class=\"g\" src=\"{}\" "
                               "alt=\"golden\"></div><figcaption>test &mdash; hover to flip to golden</figcaption>"
                               "</figure>",
                               e(*tu), e(*gu));
            else
                fmt::format_to(out, "<figure>{}<figcaption>test</figcaption></figure>",
                               img_or_missing(store, ti, "t", "test"));
        }
        if (!gi.empty())
            fmt::format_to(out, "<figure>{}<figcaption>golden ({})</figcaption></figure>",
                           img_or_missing(store, gi, "gold", "golden"), e(kind));
        if (!hi.empty()) {
            const json& fl = sub(sub(cmp, "metrics"), "flip");
            std::string blk;
            auto bx = num(fl, "block_x"), by = num(fl, "block_y");
            if (bx && by && cv != "pass")
                blk = fmt::format("<span class=\"blk\" style=\"left:{}px;top:{}px\" title=\"worst 16x16 block\"></span>",
                                  int(*bx), int(*by));
            auto hu = store.url(hi);
            if (hu)
                fmt::format_to(out,
                               "<figure><div class=\"hm\"><img class=\"heat\" src=\"{}\" alt=\"FLIP heatmap\">{}</div>"
                               "<figcaption>FLIP error heatmap{}</figcaption></figure>",
                               e(*hu), blk, blk.empty() ? "" : " (green: worst block)");
            else
                fmt::format_to(out, "<figure>{}<figcaption>FLIP heatmap</figcaption></figure>",
                               img_or_missing(store, hi, "heat", "heatmap"));
        }
        o += "</div>\n";
    }
    o += "<div class=\"cols\">";
    // Checks against tolerances.
    const json& checks = sub(cmp, "checks");
    const json& noise = sub(sub(t, "stability"), "noise_floor");
    const json& margins = sub(sub(t, "stability"), "margins");
    if (checks.is_array() && !checks.empty()) {
        const bool stab = noise.is_object() || margins.is_object();
        fmt::format_to(out, "<table class=\"grid checks\"><tr><th>metric</th><th>value</th><th>min</th><th>max</th>{}"
                            "<th>status</th></tr>",
                       stab ? "<th>noise floor</th><th>margin</th>" : "");
        for (const json& ck : checks) {
            const std::string m = str(ck, "metric"), st = str(ck, "status");
            auto cell = [&](const char* k) {
                auto v = num(ck, k);
                return v ? fmt_num(*v) : std::string("&ndash;");
            };
            std::string stab_cells;
            if (stab) {
                auto nf = num(noise, m.c_str());
                auto mg = num(margins, m.c_str());
                stab_cells = fmt::format("<td class=\"num\">{}</td><td class=\"num\">{}</td>",
                                         nf ? fmt_num(*nf) : "&ndash;", mg ? fmt_num(*mg) + "&times;" : "&ndash;");
            }
            fmt::format_to(out,
                           "<tr><td class=\"mono\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td>"
                           "<td class=\"num\">{}</td>{}<td class=\"st-{}\">{}</td></tr>",
                           e(m), cell("value"), cell("min"), cell("max"), stab_cells, e(st), e(st));
        }
        o += "</table>";
    }
    // All metrics, as written by the harness.
    const json& metrics = sub(cmp, "metrics");
    if (metrics.is_object() && !metrics.empty()) {
        o += "<dl class=\"metrics\">";
        for (auto& [group, vals] : metrics.items()) {
            if (!vals.is_object()) continue;
            std::string line;
            for (auto& [k, v] : vals.items())
                line += fmt::format("{}{} {}", line.empty() ? "" : " &middot; ", e(k), e(value_text(v)));
            fmt::format_to(out, "<dt>{}</dt><dd>{}</dd>", e(group), line);
        }
        o += "</dl>";
    }
    o += "</div>\n";
}

void timings_html(std::string& o, const json& t) {
    auto out = std::back_inserter(o);
    const json& tim = sub(t, "timings");
    auto pre = num(t, "precompute_ms"), frame = num(t, "frame_ms"), fetch = num(t, "texture_fetches_per_pixel");
    if (!(tim.is_array() && !tim.empty()) && !pre && !frame && !fetch) return;
    o += "<div><h4>Cost</h4>";
    std::vector<std::string> parts;
    if (frame) parts.push_back(fmt::format("frame (shading) <b>{} ms</b>", fmt_num(*frame)));
    if (pre) parts.push_back(fmt::format("precompute <b>{} ms</b>", fmt_num(*pre)));
    if (fetch) parts.push_back(fmt::format("texture fetches/pixel <b>{}</b>", fmt_num(*fetch)));
    std::string joined;
    for (auto& p : parts) joined += (joined.empty() ? "" : " &middot; ") + p;
    fmt::format_to(out, "<div class=\"meta\">{}</div>", joined);
    if (tim.is_array() && !tim.empty()) {
        o += "<table class=\"grid timings\"><tr><th>pass</th><th>ms</th><th>where</th><th>stage</th></tr>";
        for (const json& p : tim)
            fmt::format_to(out, "<tr><td class=\"mono\">{}</td><td class=\"num\">{}</td><td>{}</td><td>{}</td></tr>",
                           e(str(p, "pass")), fmt_num(num(p, "ms").value_or(0)), p.value("gpu", false) ? "GPU" : "CPU",
                           p.value("precompute", false) ? "precompute" : "per frame");
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
    fmt::format_to(out, "<div class=\"meta\">{} &middot; {} frames{}</div>", joined,
                   a.is_array() ? a.size() : 0, ft.size() < (a.is_array() ? a.size() : 0) ? " (some missing)" : "");
    auto strip = [&](const char* label, const std::vector<std::string>& u) {
        if (u.empty()) return;
        fmt::format_to(out, "<div class=\"strip\"><span class=\"lbl\">{}<br>frames 1&ndash;{}</span>", label,
                       std::min(u.size(), kStrip));
        for (size_t i = 0; i < u.size() && i < kStrip; ++i)
            fmt::format_to(out, "<img class=\"frame\" src=\"{}\" alt=\"{} frame {}\" title=\"{} frame {}\">", e(u[i]),
                           label, i + 1, label, i + 1);
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
                       ft.empty() ? "" : fmt::format("<figure><img class=\"pt\" src=\"{}\" alt=\"test\"><figcaption>test"
                                                     "</figcaption></figure>", e(ft[0])),
                       fr.empty() ? "" : fmt::format("<figure><img class=\"pr\" src=\"{}\" alt=\"reference\">"
                                                     "<figcaption>reference</figcaption></figure>", e(fr[0])));
    }
    o += "</div>";
}

// The overview shows the first line of a message, cut at a word near 160 characters (UTF-8 safe).
std::string short_message(const std::string& m) {
    std::string s = m.substr(0, m.find('\n'));
    if (s.size() <= 160) return s == m ? s : s + " \u2026";
    size_t cut = s.rfind(' ', 160);
    if (cut == std::string::npos || cut < 100) {
        cut = 160;
        while (cut > 0 && (static_cast<unsigned char>(s[cut]) & 0xC0) == 0x80) --cut;
    }
    return s.substr(0, cut) + " \u2026";
}

std::string test_id(size_t i) { return fmt::format("t-{}", i); }

void test_card(std::string& o, const json& t, size_t idx, ImageStore& store, const Trend& trend) {
    auto out = std::back_inserter(o);
    const std::string name = str(t, "name"), v = str(t, "verdict");
    fmt::format_to(out, "<section class=\"test s-{0} filterable\" id=\"{1}\" data-name=\"{2}\" data-verdict=\"{0}\">\n",
                   e(v), test_id(idx), e(name));
    const bool flaky = sub(t, "stability").is_object() && sub(t, "stability").value("flaky", false);
    fmt::format_to(out, "<h3><span class=\"badge v-{0}\">{0}</span> <a href=\"#{1}\">{2}</a>{3}</h3>\n", e(v),
                   test_id(idx), e(name), flaky ? " <span class=\"badge flaky\">flaky</span>" : "");
    std::vector<std::string> meta;
    for (const char* k : {"suite", "scene", "env", "method", "variant"})
        if (!str(t, k).empty()) meta.push_back(fmt::format("{} <b>{}</b>", k, e(str(t, k))));
    if (auto w = num(t, "width"), h = num(t, "height"); w && h) meta.push_back(fmt::format("{}&times;{} px", *w, *h));
    const json& opts = sub(t, "options");
    if (opts.is_object() && !opts.empty()) {
        std::string s;
        for (auto& [k, val] : opts.items()) s += (s.empty() ? "" : ",") + k + "=" + value_text(val);
        meta.push_back("options <span class=\"mono\">" + e(s) + "</span>");
    }
    const json& tags = sub(t, "tags");
    if (tags.is_array())
        for (const json& tag : tags)
            if (tag.is_string()) {
                std::string tg = tag.get<std::string>();
                bool failure = tg.rfind("failure:", 0) == 0;
                meta.push_back(failure ? "failure mode <b>" + e(tg.substr(8)) + "</b>" : "tag " + e(tg));
            }
    std::string mj;
    for (auto& m : meta) mj += (mj.empty() ? "" : " &middot; ") + m;
    fmt::format_to(out, "<div class=\"meta\">{}</div>\n", mj);
    if (const json& st = sub(t, "stability"); st.is_object()) {
        std::string line = st.value("deterministic", false) ? "bit-identical across repeats and thread counts"
                                                            : "<b>not deterministic</b>: " + e(str(st, "nondeterminism"));
        const json& sens = sub(st, "sensitivity");
        for (auto& [k, val] : sens.items())
            if (auto f = num(val, "flip.mean")) line += fmt::format(" &middot; {} {} moves FLIP by {}", e(k), e(value_text(sub(val, "value"))), fmt_num(*f));
        fmt::format_to(out, "<div class=\"meta\">stability: {}</div>\n", line);
    }
    if (!str(t, "message").empty()) fmt::format_to(out, "<div class=\"message\">{}</div>\n", e(str(t, "message")));
    if (!str(t, "driver_mismatch").empty())
        fmt::format_to(out, "<div class=\"warn\">&#9888; {} &mdash; differences may come from the platform (driver or "
                            "the CPU llvmpipe generates code for), not the shader.</div>\n",
                       e(str(t, "driver_mismatch")));
    if (needs_bless(v) && !str(t, "bless_command").empty())
        fmt::format_to(out,
                       "<div class=\"bless\"><div class=\"meta\">{}</div><div class=\"cmd\"><pre><code>{}</code></pre>"
                       "<button type=\"button\" class=\"copy\">Copy</button></div></div>\n",
                       v == "missing-golden" ? "No golden yet. To make this image the golden:"
                       : v == "improved"     ? "Closer to the reference than the golden. To accept it as the new golden:"
                                             : "If this change is intended, rebless:",
                       e(str(t, "bless_command")));
    const json& comps = sub(t, "comparisons");
    bool shown = false;
    if (comps.is_array())
        for (const json& c : comps) {
            comparison_html(o, t, c, store);
            shown = shown || !str(sub(c, "images"), "test").empty();
        }
    // No comparison shows the rendering (missing golden, size mismatch): show the test image alone,
    // from "image" or, failing that, images/<name>/test.png when that file exists.
    if (!shown) {
        std::string rel = str(t, "image");
        if (rel.empty() && !name.empty() && name.find('/') == std::string::npos && name != "." && name != "..")
            if (store.exists("images/" + name + "/test.png")) rel = "images/" + name + "/test.png";
        if (!rel.empty())
            fmt::format_to(out, "<div class=\"images\"><figure>{}<figcaption>test image{}</figcaption></figure></div>\n",
                           img_or_missing(store, rel, "t", "test"),
                           v == "missing-golden" ? " (no golden to compare with yet)" : "");
    }
    o += "<div class=\"cols\">";
    timings_html(o, t);
    const json& acc = sub(t, "accuracy");
    const json& ps = sub(t, "per_sphere");
    if (num(acc, "flip_mean") || (ps.is_array() && !ps.empty())) {
        fmt::format_to(out, "<div><h4>Accuracy vs the reference{}</h4>",
                       ps.is_array() && !ps.empty() ? " (FLIP mean per sphere)" : "");
        if (auto f = num(acc, "flip_mean"))
            fmt::format_to(out, "<div class=\"meta\">FLIP mean <b>{}</b>{}</div>", fmt_num(*f),
                           str(acc, "golden").empty() ? ""
                                                      : " against <span class=\"mono\">" + e(str(acc, "golden")) + "</span>");
        if (ps.is_array() && !ps.empty()) {
            // Compact: one row per material class, one column per roughness.
            std::map<double, std::map<int, std::vector<const json*>>> grid; // roughness -> metal? -> spheres
            for (const json& sp : ps)
                grid[num(sp, "roughness").value_or(0)][num(sp, "metallic").value_or(0) >= 0.5 ? 1 : 0].push_back(&sp);
            o += "<table class=\"grid spheres\"><tr><th>roughness</th>";
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
    o += "</div>";
    temporal_html(o, sub(t, "temporal"), store);
    if (trend.any) {
        std::string moved;
        if (!trend.flip.moved.empty()) moved += " &middot; <span class=\"moved-txt\">FLIP moved " + e(trend.flip.moved) + "</span>";
        if (!trend.frame.moved.empty()) moved += " &middot; <span class=\"moved-txt\">frame time moved " + e(trend.frame.moved) + "</span>";
        fmt::format_to(out, "<div class=\"trend\">History: <span class=\"vstrip\">{}</span>{} &middot; <a href=\"#h-{}\">trend</a></div>",
                       trend.verdict_strip, moved, idx);
    }
    o += "</section>\n";
}

std::string test_label(const json& t) {
    std::string l = str(t, "method");
    if (!str(t, "variant").empty()) l += (l.empty() ? "" : " ") + str(t, "variant");
    return l.empty() ? str(t, "name") : l;
}

std::string chart_tip(const json& t, const std::string& extra) {
    return fmt::format("{}\nscene {} · env {}\n{}", str(t, "name"), str(t, "scene"), str(t, "env"), extra);
}

// Speed against accuracy: x = a cost (per-frame, precompute, fetches), y = FLIP vs the reference.
std::string speed_chart(const std::vector<const json*>& tests, const char* cost_key, const std::string& id,
                        const std::string& title, const std::string& xlabel, bool force_log,
                        const std::vector<size_t>& order) {
    Chart c;
    c.id = id;
    c.title = title;
    c.note = "one point per test; lower-left is better; hover a point for the test";
    c.x = {xlabel, force_log, {}, {}};
    c.y = {"mean FLIP vs reference (lower is better)", false, {}, {}};
    c.pareto = true;
    std::map<std::string, size_t> by_method;
    std::vector<double> xs;
    for (size_t k = 0; k < tests.size(); ++k) {
        const json& t = *tests[k];
        auto f = num(sub(t, "accuracy"), "flip_mean");
        auto x = num(t, cost_key);
        if (!f || !x) continue;
        const std::string m = str(t, "method").empty() ? "other" : str(t, "method");
        if (!by_method.count(m)) {
            by_method[m] = c.series.size();
            c.series.push_back({m, method_color(m), false, false, {}});
        }
        ChartPoint p;
        p.x = *x;
        p.y = *f;
        p.label = test_label(t);
        p.tooltip = chart_tip(t, fmt::format("{} = {}, FLIP = {}", cost_key, fmt_num(*x), fmt_num(*f)));
        p.href = "#" + test_id(order[k]);
        c.series[by_method[m]].points.push_back(std::move(p));
        if (*x > 0) xs.push_back(*x);
    }
    if (c.series.empty()) return "";
    if (!force_log && !xs.empty()) {
        auto [mn, mx] = std::minmax_element(xs.begin(), xs.end());
        c.x.log = *mx / *mn > 20;
    }
    return render_chart(c);
}

} // namespace

void write_report(const json& results, const fs::path& results_dir, const fs::path& out_dir,
                  const std::vector<json>& history) {
    validate_results(results, (results_dir / "results.json").string());
    std::error_code ec;
    fs::create_directories(out_dir, ec);
    if (!fs::is_directory(out_dir))
        throw Error(fmt::format("{}: cannot create the report folder: {}", out_dir.string(), ec.message()));
    ImageStore store(results_dir, out_dir);

    // Failures first; the original order within a verdict.
    std::vector<const json*> tests;
    for (const json& t : results["tests"]) tests.push_back(&t);
    std::stable_sort(tests.begin(), tests.end(), [](const json* a, const json* b) {
        return verdict_rank(str(*a, "verdict")) < verdict_rank(str(*b, "verdict"));
    });
    std::vector<size_t> order(tests.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;

    std::map<std::string, int> counts;
    for (auto& v : kVerdictOrder) counts[v] = 0;
    for (const json* t : tests) counts[str(*t, "verdict")]++;
    const bool bad = counts["fail"] + counts["error"] + counts["missing-golden"] > 0;

    // History window: the stored runs plus this one (unless the harness appended it already).
    const json current = history_entry(results);
    History hist;
    std::vector<const json*> all;
    // Runs of other suites (one history file may serve several) are left out of the trend.
    for (const json& h : history)
        if (str(h, "suite").empty() || str(current, "suite").empty() || str(h, "suite") == str(current, "suite"))
            all.push_back(&h);
    if (all.empty() || str(*all.back(), "commit") != str(current, "commit") ||
        str(*all.back(), "date") != str(current, "date"))
        all.push_back(&current);
    const size_t first = all.size() > History::kMaxRuns ? all.size() - History::kMaxRuns : 0;
    hist.runs.assign(all.begin() + long(first), all.end());
    std::vector<Trend> trends;
    for (const json* t : tests) trends.push_back(trend_for(hist, str(*t, "name")));

    std::string o;
    o.reserve(1 << 16);
    auto out = std::back_inserter(o);
    const std::string suite = str(results, "suite");
    std::string title = fmt::format("iblcheck {}: ", suite.empty() ? "report" : suite);
    {
        std::string c;
        for (auto& v : kVerdictOrder)
            if (counts[v]) c += (c.empty() ? "" : ", ") + fmt::format("{} {}", counts[v], v);
        title += c.empty() ? "no tests" : c;
    }
    fmt::format_to(out,
                   "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<meta name=\"viewport\" "
                   "content=\"width=device-width, initial-scale=1\">\n<title>{}</title>\n<style>{}</style>\n</head>\n"
                   "<body data-check=\"pending\">\n<main>\n",
                   e(title), assets::kCss);

    // ---- summary ----
    fmt::format_to(out, "<header class=\"summary{}\"><h1>iblcheck report &mdash; suite {} <span class=\"badge v-{}\">{}"
                        "</span></h1>\n<div class=\"counts\">",
                   bad ? " overall-fail" : "", e(suite.empty() ? "?" : suite), bad ? "fail" : "pass",
                   bad ? "failed" : "passed");
    for (auto& v : kVerdictOrder)
        fmt::format_to(out,
                       "<button type=\"button\" class=\"count v-{0}{1}\" data-verdict=\"{0}\" data-count=\"{2}\" "
                       "title=\"show only {0} (click again: all)\">{2} {0}</button>",
                       v, counts[v] ? "" : " zero", counts[v]);
    o += "</div>\n<table class=\"info\">";
    auto row = [&](const char* k, const std::string& v_html) {
        if (!v_html.empty()) fmt::format_to(out, "<tr><th>{}</th><td>{}</td></tr>", k, v_html);
    };
    std::string commit = e(str(results, "commit"));
    if (results.value("dirty", false)) commit += " <span class=\"badge dirty\">dirty</span>";
    row("commit", commit);
    row("started", e(str(results, "started")));
    if (auto ts = num(results, "total_s")) row("total time", fmt::format("{} s", fmt_num(*ts)));
    const json& drv = sub(results, "driver");
    row("device", e(value_text(sub(drv, "device"))));
    {
        std::string d = e(value_text(sub(drv, "driver")));
        if (!value_text(sub(drv, "driver_info")).empty()) d += " &mdash; " + e(value_text(sub(drv, "driver_info")));
        row("driver", d);
        std::string v;
        for (auto [k, label] : {std::pair{"mesa", "Mesa"}, {"llvm", "LLVM"}, {"api", "Vulkan API"}})
            if (!value_text(sub(drv, k)).empty())
                v += (v.empty() ? "" : " &middot; ") + fmt::format("{} <b>{}</b>", label, e(value_text(sub(drv, k))));
        row("versions", v);
    }
    row("tests", fmt::format("{}", tests.size()));
    o += "</table>\n";
    if (!str(results, "command").empty())
        fmt::format_to(out, "<div class=\"cmd\"><pre><code>{}</code></pre><button type=\"button\" class=\"copy\">Copy"
                            "</button></div>\n",
                       e(str(results, "command")));
    if (!store.missing().empty()) { /* filled in after rendering: see below */ }
    o += "</header>\n";

    // ---- navigation and filter ----
    o += "<nav class=\"toc\" style=\"margin-top:10px\"><a href=\"#tests\">Tests</a><a href=\"#speed\">Speed vs accuracy</a>"
         "<a href=\"#roughness\">Error vs roughness</a><a href=\"#temporal\">Flicker vs FLIP</a>"
         "<a href=\"#history\">History</a></nav>\n";
    o += "<div class=\"filterbar\"><input type=\"search\" id=\"filter-text\" placeholder=\"filter by name "
         "substring, e.g. roughness_sweep or dominant_dir=\" aria-label=\"filter by name\"><span class=\"vfilter\">";
    for (auto& v : kVerdictOrder)
        fmt::format_to(out, "<label><input type=\"checkbox\" value=\"{0}\" checked> <span class=\"badge v-{0}\">{0}</span>"
                            " </label>",
                       v);
    o += "</span><button type=\"button\" id=\"filter-reset\">show all</button><span id=\"filter-count\" "
         "class=\"meta\"></span></div>\n";

    // ---- overview table ----
    o += "<h2 id=\"tests\">Tests (failures first)</h2>\n<table class=\"grid overview\"><tr><th>verdict</th><th>test</th>"
         "<th>FLIP vs golden</th><th>FLIP vs reference</th><th>frame ms</th><th>precompute ms</th>"
         "<th>fetches/px</th><th>message</th></tr>\n";
    for (size_t i = 0; i < tests.size(); ++i) {
        const json& t = *tests[i];
        const std::string v = str(t, "verdict");
        std::optional<double> golden_flip;
        if (sub(t, "comparisons").is_array())
            for (const json& c : t["comparisons"])
                if (!golden_flip) golden_flip = num(sub(sub(c, "metrics"), "flip"), "mean");
        auto cellnum = [](std::optional<double> x) { return x ? fmt_num(*x) : std::string(); };
        fmt::format_to(out,
                       "<tr class=\"filterable\" data-name=\"{2}\" data-verdict=\"{0}\"><td><span class=\"badge v-{0}\">"
                       "{0}</span></td><td><a href=\"#{1}\">{2}</a></td><td class=\"num\">{3}</td><td class=\"num\">{4}"
                       "</td><td class=\"num\">{5}</td><td class=\"num\">{6}</td><td class=\"num\">{7}</td><td class=\"msg\" "
                       "title=\"{9}\">{8}</td></tr>\n",
                       e(v), test_id(i), e(str(t, "name")), cellnum(golden_flip),
                       cellnum(num(sub(t, "accuracy"), "flip_mean")), cellnum(num(t, "frame_ms")),
                       cellnum(num(t, "precompute_ms")), cellnum(num(t, "texture_fetches_per_pixel")),
                       e(short_message(str(t, "message"))), e(str(t, "message")));
    }
    o += "</table>\n";

    // ---- failure modes: tests tagged failure:NAME, grouped, with each method's error ----
    std::map<std::string, std::vector<size_t>> modes;
    for (size_t i = 0; i < tests.size(); ++i)
        if (const json& tags = sub(*tests[i], "tags"); tags.is_array())
            for (const json& tag : tags)
                if (tag.is_string() && tag.get<std::string>().rfind("failure:", 0) == 0) modes[tag.get<std::string>().substr(8)].push_back(i);
    if (!modes.empty()) {
        o += "<h2 id=\"failure-modes\">Failure modes</h2>\n<table class=\"grid\"><tr><th>failure mode</th><th>test</th>"
             "<th>FLIP vs reference</th><th>verdict</th></tr>\n";
        for (auto& [mode, idx] : modes)
            for (size_t k = 0; k < idx.size(); ++k) {
                const json& t = *tests[idx[k]];
                auto acc = num(sub(t, "accuracy"), "flip_mean");
                fmt::format_to(out, "<tr>{}<td><a href=\"#{}\">{}</a></td><td class=\"num\">{}</td><td><span class=\"badge v-{}\">{}</span></td></tr>\n",
                               k == 0 ? fmt::format("<td rowspan=\"{}\"><b>{}</b></td>", idx.size(), e(mode)) : std::string(),
                               test_id(idx[k]), e(str(t, "name")), acc ? fmt_num(*acc) : std::string(), e(str(t, "verdict")),
                               e(str(t, "verdict")));
            }
        o += "</table>\n";
    }

    // ---- per-test cards ----
    for (size_t i = 0; i < tests.size(); ++i) test_card(o, *tests[i], i, store, trends[i]);

    // ---- speed against accuracy ----
    // Methods are compared on the same scene and environment: one row of charts per (scene, env),
    // then every test together (folded away: costs and errors of different scenes do not compare).
    auto group_of = [](const json& t) { return str(t, "scene") + " \u00b7 " + str(t, "env"); };
    auto group_id = [](std::string g) {
        for (char& ch : g)
            if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '-';
        return g;
    };
    std::map<std::string, std::vector<size_t>> groups;
    for (size_t i = 0; i < tests.size(); ++i)
        if (num(sub(*tests[i], "accuracy"), "flip_mean")) groups[group_of(*tests[i])].push_back(i);
    o += "<h2 id=\"speed\">Speed against accuracy</h2>\n<p class=\"meta\">Cost (x) against mean FLIP error vs the "
         "reference golden (y), one row per scene and environment. The dashed staircase is the Pareto front: no other "
         "test is both cheaper and more accurate than the ringed points. Frame time is per-frame shading on this driver; "
         "texture fetches per pixel do not depend on the driver.</p>\n";
    std::vector<std::pair<std::string, std::vector<size_t>>> ordered(groups.begin(), groups.end());
    std::stable_sort(ordered.begin(), ordered.end(), [](auto& a, auto& b) { return a.second.size() > b.second.size(); });
    for (auto& [g, idx] : ordered) {
        if (idx.size() < 2) continue;
        std::vector<const json*> gt;
        std::vector<size_t> go;
        for (size_t i : idx) {
            gt.push_back(tests[i]);
            go.push_back(order[i]);
        }
        const std::string id = group_id(g);
        fmt::format_to(out, "<h3>{}</h3><div class=\"charts\">", e(g));
        o += speed_chart(gt, "frame_ms", "speed-" + id, "Per-frame shading time vs error \u00b7 " + g, "frame time, ms", true, go) +
             speed_chart(gt, "texture_fetches_per_pixel", "fetches-" + id, "Texture fetches per pixel vs error \u00b7 " + g,
                         "texture fetches per pixel", false, go) +
             speed_chart(gt, "precompute_ms", "precompute-" + id, "Precompute time vs error \u00b7 " + g,
                         "precompute time, ms", true, go);
        o += "</div>\n";
    }
    o += "<details><summary>All tests in one chart</summary><div class=\"charts\">";
    {
        std::string charts = speed_chart(tests, "frame_ms", "speed-accuracy", "Per-frame shading time vs error",
                                         "frame time, ms", true, order) +
                             speed_chart(tests, "precompute_ms", "speed-accuracy-precompute",
                                         "Precompute time vs error", "precompute time, ms", true, order) +
                             speed_chart(tests, "texture_fetches_per_pixel", "speed-accuracy-fetches",
                                         "Texture fetches per pixel vs error (driver-independent)",
                                         "texture fetches per pixel", false, order);
        o += charts.empty() ? "<p class=\"meta\">No test has both a cost and an accuracy (FLIP vs a reference golden).</p>"
                            : charts;
    }
    o += "</div></details>\n";

    // ---- error against roughness: one chart per scene and environment, then all together ----
    auto roughness_chart = [&](const std::string& id, const std::string& title, const std::string& env_filter) -> std::string {
            Chart c;
            c.id = id;
            c.title = title;
            c.note = "solid: metal, dashed: dielectric; one colour per test (method, variant, environment)";
            c.x = {"roughness", false, 0.0, 1.0};
            c.y = {"mean FLIP vs reference", false, {}, {}};
            size_t colour = 0;
            for (size_t i = 0; i < tests.size(); ++i) {
                const json& t = *tests[i];
                if (!env_filter.empty() && group_of(t) != env_filter) continue;
                const json& ps = sub(t, "per_sphere");
                if (!ps.is_array() || ps.empty()) continue;
                const std::string col = kPalette[colour++ % std::size(kPalette)];
                std::string base = test_label(t);
                if (!str(t, "env").empty()) base += " \u00b7 " + str(t, "env");
                ChartSeries metal{base + " \u00b7 metal", col, false, true, {}};
                ChartSeries diel{base + " \u00b7 dielectric", col, true, true, {}};
                for (const json& s : ps) {
                    const double m = num(s, "metallic").value_or(0);
                    ChartPoint p;
                    p.x = num(s, "roughness").value_or(0);
                    p.y = num(s, "flip_mean").value_or(0);
                    p.tooltip = fmt::format("{}\n{}: roughness {}, metallic {}, FLIP {}", str(t, "name"), str(s, "label"),
                                            fmt_num(p.x), fmt_num(m), fmt_num(p.y));
                    p.href = "#" + test_id(i);
                    (m >= 0.5 ? metal : diel).points.push_back(std::move(p));
                }
                if (!metal.points.empty()) c.series.push_back(std::move(metal));
                if (!diel.points.empty()) c.series.push_back(std::move(diel));
            }
            return c.series.empty() ? std::string() : render_chart(c);
    };
    o += "<h2 id=\"roughness\">Error against roughness</h2>\n<div class=\"charts\">";
    {
        std::set<std::string> with_spheres;
        for (const json* t : tests)
            if (sub(*t, "per_sphere").is_array() && !sub(*t, "per_sphere").empty()) with_spheres.insert(group_of(*t));
        for (const auto& g : with_spheres)
            o += roughness_chart("error-roughness-" + group_id(g), "Per-sphere FLIP vs the reference \u00b7 " + g, g);
        std::string all = roughness_chart("error-roughness", "Per-sphere FLIP vs the reference, by roughness (all tests)", "");
        o += all.empty() ? "<p class=\"meta\">No test has per-sphere errors.</p>"
                         : "</div><details><summary>All tests in one chart</summary><div class=\"charts\">" + all + "</div></details><div>";
    }
    o += "</div>\n";

    // ---- flicker against FLIP ----
    o += "<h2 id=\"temporal\">Flicker against FLIP (temporal tests)</h2>\n<div class=\"charts\">";
    {
        Chart c;
        c.id = "flicker-flip";
        c.title = "Temporal flicker vs mean FLIP";
        c.note = "x: mean FLIP over the frames vs the reference; y: flicker; lower-left is better";
        c.x = {"mean FLIP vs reference", false, {}, {}};
        c.y = {"flicker", false, {}, {}};
        std::map<std::string, size_t> by_method;
        for (size_t i = 0; i < tests.size(); ++i) {
            const json& t = *tests[i];
            const json& tp = sub(t, "temporal");
            auto fl = num(tp, "flicker");
            auto fm = num(tp, "flip_mean");
            if (!fm) fm = num(sub(t, "accuracy"), "flip_mean");
            if (!fl || !fm) continue;
            const std::string m = str(t, "method").empty() ? "other" : str(t, "method");
            if (!by_method.count(m)) {
                by_method[m] = c.series.size();
                c.series.push_back({m, method_color(m), false, false, {}});
            }
            ChartPoint p;
            p.x = *fm;
            p.y = *fl;
            p.label = test_label(t);
            p.tooltip = chart_tip(t, fmt::format("FLIP = {}, flicker = {}", fmt_num(*fm), fmt_num(*fl)));
            p.href = "#" + test_id(i);
            c.series[by_method[m]].points.push_back(std::move(p));
        }
        o += c.series.empty() ? "<p class=\"meta\">No temporal test in this run.</p>" : render_chart(c);
    }
    o += "</div>\n";

    // ---- history ----
    o += "<h2 id=\"history\">History</h2>\n";
    if (hist.runs.size() < 2) {
        o += "<p class=\"meta\">No history: pass <code>--history FILE</code> (JSON lines, one entry per run) to see "
             "trends.</p>\n";
    } else {
        fmt::format_to(out,
                       "<p class=\"meta\">The last {} runs, oldest left, this run right (blue). A red mark labels the "
                       "commit of the largest step in a test's value when it moved by more than 10&nbsp;%.</p>\n",
                       hist.runs.size());
        o += "<table class=\"grid history\"><tr><th>test</th><th>verdicts</th><th>FLIP vs reference</th><th>moved</th>"
             "<th>frame ms</th><th>moved</th></tr>\n";
        for (size_t i = 0; i < tests.size(); ++i) {
            const Trend& tr = trends[i];
            const std::string v = str(*tests[i], "verdict");
            fmt::format_to(out,
                           "<tr class=\"filterable\" id=\"h-{0}\" data-name=\"{1}\" data-verdict=\"{2}\"><td><a "
                           "href=\"#{3}\">{1}</a></td><td><span class=\"vstrip\">{4}</span></td><td>{5}</td><td "
                           "class=\"moved-txt\">{6}</td><td>{7}</td><td class=\"moved-txt\">{8}</td></tr>\n",
                           i, e(str(*tests[i], "name")), e(v), test_id(i), tr.verdict_strip,
                           tr.flip.points ? tr.flip.svg + " <span class=\"meta\">" + e(tr.flip.range) + "</span>" : "",
                           e(tr.flip.moved),
                           tr.frame.points ? tr.frame.svg + " <span class=\"meta\">" + e(tr.frame.range) + "</span>" : "",
                           e(tr.frame.moved));
        }
        o += "</table>\n";
    }

    if (!store.missing().empty()) {
        o += "<h2>Missing images</h2><ul class=\"mono\">";
        for (auto& m : store.missing()) fmt::format_to(out, "<li>{}</li>", e(m));
        o += "</ul>";
    }
    fmt::format_to(out,
                   "<footer>Written by <code>iblcheck report</code> from results schema iblcheck-results/1. Rebuild "
                   "it with <code>iblcheck report RESULTS.json --out DIR [--history FILE]</code>. Static and offline: "
                   "open index.html from the file system.</footer>\n</main>\n<script>{}</script>\n</body></html>\n",
                   assets::kJs);

    const fs::path index = out_dir / "index.html";
    const fs::path tmp = out_dir / "index.html.tmp";
    {
        std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
        if (!f) throw Error(fmt::format("{}: cannot write the report", tmp.string()));
        f << o;
        if (!f) throw Error(fmt::format("{}: write failed", tmp.string()));
    }
    fs::rename(tmp, index, ec);
    if (ec) throw Error(fmt::format("{}: cannot write the report: {}", index.string(), ec.message()));
}

} // namespace iblcheck::report
