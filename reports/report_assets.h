// The report's style sheet and script, as files: reports/assets/report.css and reports/assets/report.js,
// embedded at build time (cmake/embed_assets.cmake writes them into report_assets_embedded.h in the
// build tree, every byte as it is in the file). Edit the files; the page carries them unchanged, inside
// <style> and <script> (no external assets: the page opens offline from file://).
//
// report.js is plain ES5-style script, no library, nothing fetched. The writer puts
// `window.IBLCHECK_CFG = {aces: [6 coefficients], magma: [768 values 0..255]}` before it, taken from the
// C++ the harness itself uses (the display transform's tone curve and FLIP's colour map), so exposure 0
// and scale 0-1 match the PNGs. It holds:
// - tabs (tests, charts, history, table) from the URL hash; the name/verdict filter;
// - passing tests' tiles open their folded card; comparisons inside a card switch by buttons;
// - the image viewer: data/<key>.js scripts (float_data.h) decoded to floats; exposure slider with
//   auto exposure; test/golden switch (and blink); zoom with nearest-neighbour pixels; a magnifier
//   on the worst 16x16 block that follows the pointer (click pins it); the FLIP heatmap on a chosen
//   scale with its colour bar and the exceedance mask; the sphere and values under the pointer;
// - the load check tests/test_report.cpp reads back from <body>: images, data scripts, viewers.
// buildViewer() is ~110 lines on purpose: one closure that holds a viewer's state (exposure, zoom, mask,
// the pinned block) and the handlers that read and redraw it; split, the state would travel in arguments.
#pragma once

#include "reports/report_assets_embedded.h" // iblcheck::report::assets::kCss, kJs (std::string_view)
