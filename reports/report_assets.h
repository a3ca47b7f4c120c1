// The report's inline CSS (no external assets: the page opens offline from file://). The page's
// script is in report_script.h.
#pragma once

namespace iblcheck::report::assets {

inline constexpr const char* kCss = R"CSS(
:root{--pass:#2b8a3e;--fail:#c92a2a;--improved:#1971c2;--missing:#e67700;--error:#862e9c;--bg:#f8f9fa;--fg:#212529;--mut:#868e96;--line:#dee2e6}
*{box-sizing:border-box}
body{margin:0;font:14px/1.4 system-ui,-apple-system,"Segoe UI",Roboto,"DejaVu Sans",sans-serif;color:var(--fg);background:var(--bg)}
main{padding:10px 18px 30px;max-width:1900px}
h1{font-size:19px;margin:0}h2{font-size:16px;margin:18px 0 8px;border-bottom:2px solid var(--line);padding-bottom:3px}
h3{font-size:15px;margin:0;word-break:break-all;display:inline}h4{font-size:13px;margin:10px 0 4px;color:#495057}
a{color:#1864ab}
code,pre,.mono{font-family:"DejaVu Sans Mono",Menlo,Consolas,monospace;font-size:12.5px}
header.summary{background:#fff;border:1px solid var(--line);border-left:8px solid var(--pass);padding:8px 14px;border-radius:6px}
header.summary.overall-fail{border-left-color:var(--fail)}
.hrow{display:flex;gap:16px;align-items:center;flex-wrap:wrap}
.counts{display:flex;gap:6px;flex-wrap:wrap}
.count{border:0;border-radius:5px;padding:3px 10px;color:#fff;font-weight:600;font-size:13px;cursor:pointer}
.count.zero{opacity:.35}
.badge{display:inline-block;border-radius:4px;padding:1px 7px;color:#fff;font-weight:600;font-size:11.5px;text-transform:uppercase;vertical-align:middle}
.v-pass{background:var(--pass)}.v-fail{background:var(--fail)}.v-improved{background:var(--improved)}.v-missing-golden{background:var(--missing)}.v-error{background:var(--error)}
.dirty{background:#f08c00}.flaky{background:#5f3dc4}.v-none{background:#dee2e6}
.facts{color:#495057;font-size:12.5px;margin:4px 0}
.facts b{color:var(--fg);font-weight:600}
.hcols{display:flex;gap:18px;flex-wrap:wrap;align-items:flex-start}
table{border-collapse:collapse}
table.since{font-size:12.5px}table.since th,table.since td{padding:1px 12px 1px 0;text-align:left;vertical-align:top}
table.since th{color:var(--mut);font-weight:500}table.since td.changed{color:var(--fail);font-weight:600}table.since td.same{color:var(--pass)}
table.grid{background:#fff;border:1px solid var(--line);font-size:12.5px}
table.grid th,table.grid td{border-bottom:1px solid var(--line);padding:2px 8px;text-align:left;vertical-align:top}
table.grid th{background:#f1f3f5;font-weight:600}
table.grid td.num{text-align:right;font-variant-numeric:tabular-nums;font-family:"DejaVu Sans Mono",monospace;font-size:12px}
td.st-fail,td.st-error{color:var(--fail);font-weight:700}td.st-pass{color:var(--pass)}td.st-improved{color:var(--improved);font-weight:700}
.cmd{display:flex;align-items:flex-start;gap:6px;margin:4px 0}
.cmd .lbl{color:#495057;font-size:12.5px;padding-top:4px;white-space:nowrap}
.cmd pre{margin:0;padding:4px 8px;background:#212529;color:#f8f9fa;border-radius:4px;white-space:pre-wrap;word-break:break-all;flex:0 1 auto;user-select:all}
button{font:inherit;font-size:12px;padding:2px 8px;cursor:pointer;border:1px solid #adb5bd;border-radius:4px;background:#fff}
button.on{background:#343a40;color:#fff;border-color:#343a40}
nav.tabs{position:sticky;top:0;z-index:6;background:var(--bg);display:flex;gap:4px;align-items:flex-end;border-bottom:2px solid var(--line);margin:8px 0 0;padding-top:4px;flex-wrap:wrap}
nav.tabs a{padding:5px 14px;border:1px solid var(--line);border-bottom:0;border-radius:6px 6px 0 0;text-decoration:none;color:#495057;background:#f1f3f5;font-weight:600}
nav.tabs a.on{background:#fff;color:var(--fg);border-color:#adb5bd}
nav.tabs .filter{margin-left:auto;display:flex;gap:8px;align-items:center;padding-bottom:4px;font-size:12.5px}
nav.tabs input[type=search]{font-size:13px;padding:3px 6px;width:230px}
section.test{background:#fff;border:1px solid var(--line);border-left:6px solid var(--pass);border-radius:6px;padding:8px 12px;margin:10px 0}
section.test.s-fail{border-left-color:var(--fail)}section.test.s-error{border-left-color:var(--error)}section.test.s-missing-golden{border-left-color:var(--missing)}section.test.s-improved{border-left-color:var(--improved)}
.thead{display:flex;gap:8px;align-items:baseline;flex-wrap:wrap}.thead .fold{margin-left:auto}
.meta{color:var(--mut);font-size:12.5px;margin:1px 0 3px}
ul.why{margin:3px 0;padding-left:18px;font-family:"DejaVu Sans Mono",monospace;font-size:12.5px}ul.why li.acc{color:#1864ab}
.warn{background:#fff3bf;border:1px solid #fab005;border-radius:4px;padding:3px 8px;margin:4px 0;font-size:12.5px}
.cmp-tabs{display:flex;gap:4px;margin:6px 0 2px;align-items:center;flex-wrap:wrap}
.cmp-head{font-size:12.5px;color:#495057;margin:2px 0}
.vbar{display:flex;gap:14px;flex-wrap:wrap;align-items:center;font-size:12.5px;background:#f1f3f5;border-radius:4px;padding:3px 8px;margin:3px 0}
.vbar label{display:inline-flex;gap:4px;align-items:center;white-space:nowrap}
.vbar input[type=range]{width:190px}.vbar output{display:inline-block;min-width:92px;font-family:"DejaVu Sans Mono",monospace}
.vbar input[type=number]{width:70px;font-size:12px}
.vbody{display:flex;gap:14px;flex-wrap:wrap;align-items:flex-start}
.vmain{display:flex;flex-direction:column;gap:4px;max-width:100%;overflow-x:auto}
figure{margin:0}figcaption{font-size:12px;color:var(--mut);margin-top:1px}
.stage{position:relative;display:inline-block;line-height:0;outline:1px solid var(--line);cursor:crosshair}
.stage canvas,.stage img,.mags canvas{image-rendering:crisp-edges;image-rendering:pixelated}
img{max-width:none;display:block}
.stage img.g{display:none}
.blk{position:absolute;outline:2px solid #40c057;pointer-events:none}
.ptr{position:absolute;pointer-events:none;background:rgba(33,37,41,.85);color:#fff;font:11.5px/1.3 system-ui,sans-serif;padding:1px 5px;border-radius:3px;white-space:nowrap;transform:translate(10px,-120%)}
.cbar{position:relative;height:30px;margin:2px 0 0 6px;width:262px}.cbar canvas{width:256px;height:12px;display:block;outline:1px solid var(--line)}
.cbar .tk{position:absolute;top:13px;font-size:10.5px;color:#495057;transform:translateX(-50%);line-height:1.2}
.cbar .tk:before{content:"";position:absolute;left:50%;top:-3px;height:3px;border-left:1px solid #495057}
.cbar .tol{position:absolute;top:-4px;width:0;height:20px;border-left:2px dashed #00b8d4}
.vmag{width:150px}.vmag .mags{display:flex;flex-direction:column;gap:2px}.vmag canvas{width:144px;height:144px;outline:1px solid var(--line);display:block}
.vmag figcaption{font-size:11px}.vmag button{margin-top:3px}
.vmag .mlbl{font-size:11.5px;color:var(--mut);text-align:center;line-height:1.3}
.readout{font-size:12px;color:#343a40;min-height:17px;margin:2px 0}
.noimg{display:inline-block;padding:14px;border:1px dashed var(--fail);color:var(--fail);font-size:12px}
.cols{display:flex;gap:20px;flex-wrap:wrap;align-items:flex-start;margin-top:4px}
details.more summary{cursor:pointer;color:#495057;font-size:12.5px;margin:4px 0}
dl.metrics{display:grid;grid-template-columns:auto auto;gap:1px 10px;margin:0;font-size:12px}dl.metrics dt{color:var(--mut)}dl.metrics dd{margin:0;font-family:"DejaVu Sans Mono",monospace}
.tiles{display:grid;grid-template-columns:repeat(auto-fill,minmax(250px,1fr));gap:6px;grid-auto-flow:dense;margin-top:6px}
.tile{background:#fff;border:1px solid var(--line);border-left:4px solid var(--pass);border-radius:5px;padding:4px 6px;cursor:pointer;min-width:0}
.tile:hover,.tile.open{border-color:#495057}
.tile img.thumb{width:100%;height:60px;object-fit:contain;object-position:left center;image-rendering:auto;background:#f1f3f5}
.tile .tl1{font-size:12.5px;font-weight:600;white-space:nowrap;overflow:hidden;text-overflow:ellipsis}
.tile .tl2{font-size:11.5px;color:var(--mut);white-space:nowrap;overflow:hidden;text-overflow:ellipsis}
.tiles>section.test{grid-column:1/-1;margin:2px 0 8px}
.strip{display:flex;gap:4px;align-items:center;overflow-x:auto;margin:4px 0}.strip .lbl{width:78px;flex:none;font-size:12px;color:var(--mut)}
.strip img{image-rendering:pixelated}
.player{display:flex;gap:10px;align-items:center;flex-wrap:wrap;margin:6px 0}
.trend{font-size:12.5px;margin-top:4px}.moved-txt{color:var(--fail);font-weight:600}
.legend-html{display:flex;gap:14px;flex-wrap:wrap;font-size:12.5px;margin:4px 0 8px;align-items:center}
.legend-html svg{vertical-align:middle}
svg.chart{background:#fff;border:1px solid var(--line);border-radius:6px;margin:4px 8px 8px 0;font-family:system-ui,"DejaVu Sans",sans-serif}
svg.chart .ctitle{font-size:13px;font-weight:600}svg.chart .cnote{font-size:11px;fill:#868e96}
svg.chart .plot{fill:#fcfcfd;stroke:#adb5bd}svg.chart .grid{stroke:#eceef0}svg.chart .tick{stroke:#868e96}
svg.chart .tl{font-size:10.5px;fill:#495057}svg.chart .al{font-size:11.5px;fill:#212529}
svg.chart .pl{font-size:10px;fill:#343a40}svg.chart .legend text{font-size:11.5px;fill:#212529}
svg.chart polyline{fill:none;stroke-width:1.8}svg.chart line.series,svg.chart .legend line{stroke-width:2}
svg.chart .dashed{stroke-dasharray:5 3}
svg.chart .pareto-front{fill:none;stroke:#212529;stroke-width:1.5;stroke-dasharray:6 4}
svg.chart .front-ring{fill:none;stroke:#212529;stroke-width:1.2}
svg.chart .point{stroke:#fff;stroke-width:.8}svg.chart .point:hover{stroke:#000;stroke-width:2}
svg.chart .point.hollow{stroke-width:1.6}
svg.chart line.range{stroke-width:1.6;opacity:.75}
svg.spark{border:0;margin:0;background:transparent;vertical-align:middle}
svg.spark .sl{stroke:#495057;stroke-width:1.3}svg.spark .point{fill:#495057;stroke:none}svg.spark .last{fill:#1971c2}
svg.spark line.rg{stroke:#adb5bd;stroke-width:2}
svg.spark line.moved{stroke:#e03131;stroke-dasharray:2 2}svg.spark text.moved{font-size:9.5px;fill:#e03131}
.vstrip{display:inline-flex;gap:1px}.vstrip span{width:6px;height:14px;display:inline-block}
.charts{display:flex;flex-wrap:wrap}
footer{color:var(--mut);font-size:12px;margin-top:20px}
[hidden]{display:none!important}
section.group{border-left:4px solid var(--fail);padding-left:10px;margin:8px 0 16px}
h2.ghead{font-size:15px;margin:4px 0}
details.gmore>summary{cursor:pointer;color:var(--mut);font-size:13px;margin:6px 0}
table.since td.info{color:var(--mut)}
table.sortable th[data-sort]{cursor:pointer}table.sortable th[data-dir=asc]::after{content:" \25B2"}table.sortable th[data-dir=desc]::after{content:" \25BC"}
.fclegend{display:inline-flex;font-size:10px;vertical-align:middle}.fclegend span{padding:1px 3px;color:#fff;text-shadow:0 0 2px #000}
table.sortable{max-width:100%}table.sortable td:nth-child(2){word-break:break-all}
)CSS";

} // namespace iblcheck::report::assets
