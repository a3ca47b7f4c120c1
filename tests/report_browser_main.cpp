// report_browser: opens a report in headless Chromium (tests/browser.h), waits for its load check,
// prints the page height and any error the page logged, and writes a screenshot. Used by
// scripts/report_screenshots.sh for the screenshots committed under reports/screenshots/.
//
//   report_browser INDEX.html --out shot.png [--width 1440] [--height 900] [--full] [--tab charts] [--js EXPR]
//                  [--scroll-to ID]   (the element with that id at the top of the screen)
//
// Exit 0, or 1 when the page logged an error or an image or data script failed to load.
#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include <filesystem>
#include <fstream>

#include "tests/browser.h"

int main(int argc, char** argv) {
    namespace fs = std::filesystem;
    CLI::App app{"Screenshot an iblcheck report in headless Chromium"};
    std::string index, out, tab, scroll_to;
    int width = 1440, height = 900;
    bool full = false;
    app.add_option("index", index, "index.html of a report")->required()->check(CLI::ExistingFile);
    app.add_option("--out", out, "PNG to write")->required();
    app.add_option("--width", width, "viewport width, CSS pixels");
    app.add_option("--height", height, "viewport height, CSS pixels");
    app.add_option("--tab", tab, "tests (default), charts, history or table");
    app.add_option("--scroll-to", scroll_to, "id of an element to scroll to the top of the screen (e.g. aa-verdict)");
    std::string js;
    app.add_flag("--full", full, "the whole page, not the first screen");
    app.add_option("--js", js, "JavaScript to run before the screenshot (e.g. pick the viewer's false colour)");
    CLI11_PARSE(app, argc, argv);
    // The id goes into a script: letters, digits, '-' and '_' only.
    if (scroll_to.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-_") != std::string::npos) {
        fmt::print(stderr, "--scroll-to '{}': an element id of letters, digits, '-' and '_'\n", scroll_to);
        return 2;
    }
    if (!iblcheck::testutil::Browser::available()) {
        fmt::print(stderr, "{} is not installed (Debian package chromium)\n", iblcheck::testutil::Browser::kChromium);
        return 2;
    }
    const fs::path profile = fs::temp_directory_path() / fmt::format("iblcheck_report_browser_{}", ::getpid());
    int rc = 0;
    {
        iblcheck::testutil::Browser b(profile, width, height);
        const std::string url = "file://" + fs::absolute(index).string() + (tab.empty() ? "" : "#" + tab);
        b.open(url, "document.body && document.body.getAttribute('data-check') === 'done'", 60);
        if (!scroll_to.empty() && !b.eval("(() => { const e = document.getElementById('" + scroll_to +
                                          "'); if (e) e.scrollIntoView(); return !!e; })()")
                                       .get<bool>()) {
            fmt::print(stderr, "{}: no element with id '{}'\n", index, scroll_to);
            rc = 1;
        }
        const auto facts =
            b.eval("({height: document.documentElement.scrollHeight, images: +document.body.getAttribute('data-images-failed'), "
                   "data: +document.body.getAttribute('data-data-failed'), viewers: "
                   "+document.body.getAttribute('data-viewers-failed')})");
        fmt::print("{}: page height {} px at {}x{}{}\n", index, facts["height"].get<int>(), width, height,
                   tab.empty() ? "" : " (tab " + tab + ")");
        for (const std::string& e : b.errors()) fmt::print("page error: {}\n", e);
        if (facts["images"] != 0 || facts["data"] != 0 || facts["viewers"] != 0) {
            fmt::print("failed to load: {} images, {} data scripts, {} viewers\n", facts["images"].get<int>(),
                       facts["data"].get<int>(), facts["viewers"].get<int>());
            rc = 1;
        }
        if (!b.errors().empty()) rc = 1;
        if (!js.empty()) b.eval(js);
        std::ofstream(out, std::ios::binary) << b.screenshot(full);
        fmt::print("screenshot: {}\n", out);
    }
    fs::remove_all(profile);
    return rc;
}
