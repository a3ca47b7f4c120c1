// The image viewer of a test card (report_html.h). Its markup works without its script (the
// PNGs); the script (assets/report.js) swaps in canvases drawn from the float data once it has loaded.
#include <cmath>
#include <iterator>

#include <fmt/format.h>

#include "reports/report_html.h"

namespace iblcheck::report::html {

namespace {

std::string img_tag(ImageStore& store, const std::string& rel, const char* cls, const std::string& alt) {
    if (rel.empty()) return "";
    if (auto u = store.url(rel)) return fmt::format("<img class=\"{}\" src=\"{}\" alt=\"{}\">", cls, e(*u), e(alt));
    return fmt::format("<div class=\"noimg\">missing image:<br><span class=\"mono\">{}</span></div>", e(rel));
}

// The spheres of the layout, for the id map's data script: {label, roughness, metallic}.
json spheres_of(const json& t) {
    const json& sp = sub(sub(t, "layout"), "spheres");
    json a = json::array();
    if (sp.is_array())
        for (const json& s : sp)
            a.push_back({{"label", str(s, "label")},
                         {"roughness", std::round(num(s, "roughness").value_or(0) * 1e4) / 1e4},
                         {"metallic", std::round(num(s, "metallic").value_or(0) * 1e4) / 1e4}});
    return a;
}

} // namespace

namespace {

// The viewer's data attributes: the float data scripts of the test, golden, error and id maps (a
// golden or error map of another size is left out), and the worst block.
std::string viewer_attrs(PageContext& ctx, const json& t, const ViewerSpec& vs, const std::optional<FloatImageInfo>& ti,
                         const std::optional<FloatImageInfo>& gi, const std::optional<FloatImageInfo>& ei) {
    std::string attrs;
    if (ti) {
        auto ids = ctx.data.id_map(str(sub(t, "layout"), "id_map"), spheres_of(t));
        attrs += fmt::format(" data-test=\"{}\"", ti->key);
        if (gi && gi->width == ti->width && gi->height == ti->height) attrs += fmt::format(" data-golden=\"{}\"", gi->key);
        if (ei && ei->width == ti->width && ei->height == ti->height) attrs += fmt::format(" data-error=\"{}\"", ei->key);
        if (ids) attrs += fmt::format(" data-ids=\"{}\"", *ids);
    }
    if (vs.block_x && vs.block_y) attrs += fmt::format(" data-bx=\"{}\" data-by=\"{}\"", *vs.block_x, *vs.block_y);
    return attrs;
}

// The controls over live images: exposure, test/golden buttons and blink, zoom, FLIP scale and mask.
void viewer_toolbar(std::string& o, const ViewerSpec& vs, bool has_golden, bool has_heat) {
    auto out = std::back_inserter(o);
    o += "<div class=\"vbar\"><label>exposure <input type=\"range\" class=\"ev\" min=\"-12\" max=\"12\" step=\"0.1\" "
         "value=\"0\" aria-label=\"exposure in stops\"></label><output class=\"evv\">0.0 EV</output>"
         "<button type=\"button\" class=\"ev-auto\" title=\"this image's automatic exposure\">auto</button>"
         "<button type=\"button\" class=\"ev-0\" title=\"the PNG's exposure\">0 EV</button>"
         // Display only (issue 32): under a 1e5 sun one exposure blows out half the spheres.
         "<select class=\"dmode\" aria-label=\"display\" title=\"display only: the scores do not change\"><option "
         "value=\"exp\">one exposure</option><option value=\"sphere\">exposure per sphere</option><option "
         "value=\"false\">false colour (stops)</option></select><span class=\"fclegend\" hidden></span>";
    if (has_golden)
        fmt::format_to(out,
                       "<span><button type=\"button\" class=\"show on\" data-show=\"test\">test</button><button "
                       "type=\"button\" class=\"show\" data-show=\"golden\">{}</button> <label><input type=\"checkbox\" "
                       "class=\"blink\"> blink</label></span>",
                       e(vs.golden_name));
    o += "<span class=\"zooms\">zoom";
    for (int z : {1, 2, 3, 4, 6, 8})
        fmt::format_to(out, "<button type=\"button\" class=\"z\" data-z=\"{0}\">{0}&times;</button>", z);
    o += "</span>";
    if (has_heat)
        fmt::format_to(out,
                       "<label>FLIP scale <select class=\"escale\"><option value=\"auto\">auto</option><option "
                       "value=\"1\">0&ndash;1</option><option value=\"0.5\">0&ndash;0.5</option><option value=\"0.2\">"
                       "0&ndash;0.2</option><option value=\"0.1\">0&ndash;0.1</option><option value=\"0.05\">0&ndash;"
                       "0.05</option><option value=\"0.02\">0&ndash;0.02</option><option value=\"0.01\">0&ndash;0.01"
                       "</option></select></label><label title=\"{}\"><input type=\"checkbox\" class=\"mask\"> mask "
                       "FLIP &gt; <input type=\"number\" class=\"tol\" min=\"0\" max=\"1\" step=\"0.001\" value=\"{}\">"
                       "</label>",
                       e(vs.tol_note), vs.tol);
    o += "</div>\n";
}

// No float data (results without EXRs, e.g. from an older harness): the PNGs side by side; closes
// the viewer.
void viewer_static(std::string& o, PageContext& ctx, const ViewerSpec& vs, bool has_golden, bool has_heat) {
    auto out = std::back_inserter(o);
    o += "<div class=\"vbody\">";
    fmt::format_to(out, "<figure>{}<figcaption>test</figcaption></figure>", img_tag(ctx.images, vs.test_png, "t", "test"));
    if (has_golden)
        fmt::format_to(out, "<figure>{}<figcaption>{}</figcaption></figure>",
                       img_tag(ctx.images, vs.golden_png, "gold", vs.golden_name), e(vs.golden_name));
    if (has_heat)
        fmt::format_to(out, "<figure>{}<figcaption>FLIP per pixel (magma, 0&ndash;1){}</figcaption></figure>",
                       img_tag(ctx.images, vs.heat_png, "heat", "FLIP heatmap"),
                       vs.block_x ? fmt::format("; worst 16&times;16 block at ({},{})", *vs.block_x, *vs.block_y) : "");
    o += "</div></div>\n";
}

// The test image (the golden's PNG under it for the buttons) and the FLIP heatmap with its colour
// bar when the error map has float data, each a stage the script draws canvases on.
void viewer_stages(std::string& o, PageContext& ctx, const ViewerSpec& vs, bool has_golden, bool has_heat, bool error_data) {
    auto out = std::back_inserter(o);
    o += "<div class=\"vmain\">";
    auto blk = [&] {
        return vs.block_x ? std::string("<span class=\"blk\" title=\"worst 16x16 block\"></span>") : std::string();
    };
    fmt::format_to(out,
                   "<figure class=\"vimg\"><div class=\"stage\">{}{}<canvas class=\"cv-img\" hidden></canvas>{}"
                   "<span class=\"ptr\" hidden></span></div><figcaption>{}</figcaption></figure>",
                   img_tag(ctx.images, vs.test_png, "png t", "test"),
                   has_golden ? img_tag(ctx.images, vs.golden_png, "png g", vs.golden_name) : "", blk(),
                   has_golden ? "test (buttons: " + e(vs.golden_name) + "); pointer: sphere and values; click: pin the magnifier"
                              : "test");
    if (has_heat) {
        fmt::format_to(out,
                       "<figure class=\"verr\"><div class=\"stage\">{}<canvas class=\"cv-err\" hidden></canvas>{}"
                       "<span class=\"ptr\" hidden></span></div>",
                       img_tag(ctx.images, vs.heat_png, "png heat", "FLIP heatmap"), blk());
        if (error_data)
            o += "<div class=\"cbar\"><canvas></canvas><span class=\"tk\" style=\"left:0\"></span><span class=\"tk\" "
                 "style=\"left:64px\"></span><span class=\"tk\" style=\"left:128px\"></span><span class=\"tk\" "
                 "style=\"left:192px\"></span><span class=\"tk\" style=\"left:256px\"></span><span class=\"tol\" "
                 "title=\"mask threshold\"></span></div>";
        fmt::format_to(out,
                       "<figcaption>FLIP per pixel vs the {} (magma{}){} <span class=\"maskinfo\"></span></figcaption></figure>",
                       e(vs.golden_name), error_data ? ", scale on the bar" : " 0&ndash;1",
                       vs.block_x ? "; green: the worst 16&times;16 block" : "");
    }
    o += "</div>";
}

// The magnifier over the worst block: test, golden and FLIP side by side.
void viewer_magnifier(std::string& o, const ViewerSpec& vs, bool has_golden, bool has_heat) {
    fmt::format_to(std::back_inserter(o),
                   "<figure class=\"vmag\"><div class=\"mags\"><div><canvas class=\"mg-t\"></canvas><div class=\"mlbl\">"
                   "test</div></div>{}{}</div><figcaption class=\"mcap\">worst 16&times;16 block ({},{}){}</figcaption>"
                   "<button type=\"button\" class=\"worst\">back to the worst block</button></figure>",
                   has_golden ? "<div><canvas class=\"mg-g\"></canvas><div class=\"mlbl\">" + e(vs.golden_name) + "</div></div>"
                              : "",
                   has_heat ? "<div><canvas class=\"mg-e\"></canvas><div class=\"mlbl\">FLIP</div></div>" : "", *vs.block_x,
                   *vs.block_y, vs.block_sphere.empty() ? "" : " on " + e(vs.block_sphere));
}

} // namespace

void viewer_html(std::string& o, PageContext& ctx, const json& t, const ViewerSpec& vs) {
    auto ti = ctx.data.image(vs.test_exr);
    auto gi = ti ? ctx.data.image(vs.golden_exr) : std::nullopt;
    auto ei = ti ? ctx.data.image(vs.error_exr) : std::nullopt;
    const bool live = ti.has_value();
    fmt::format_to(std::back_inserter(o), "<div class=\"viewer\"{} data-tol=\"{}\" data-golden-name=\"{}\">\n",
                   viewer_attrs(ctx, t, vs, ti, gi, ei), vs.tol, e(vs.golden_name));
    const bool has_golden = !vs.golden_png.empty(), has_heat = !vs.heat_png.empty();
    if (!live) {
        viewer_static(o, ctx, vs, has_golden, has_heat);
        return;
    }
    viewer_toolbar(o, vs, has_golden, has_heat);
    o += "<div class=\"vbody\">";
    viewer_stages(o, ctx, vs, has_golden, has_heat, ei.has_value());
    if (vs.block_x) viewer_magnifier(o, vs, has_golden, has_heat);
    o += "</div>";
    o += "<div class=\"readout mono\">point at an image: pixel, sphere, linear values</div>";
    o += "</div>\n";
}

} // namespace iblcheck::report::html
