// The report's inline CSS and JavaScript (no external assets: the page opens offline from file://).
#pragma once

namespace iblcheck::report::assets {

inline constexpr const char* kCss = R"CSS(
:root{--pass:#2b8a3e;--fail:#c92a2a;--improved:#1971c2;--missing:#e67700;--error:#862e9c;--bg:#f8f9fa;--fg:#212529;--mut:#868e96;--line:#dee2e6}
*{box-sizing:border-box}
body{margin:0;font:14px/1.45 system-ui,-apple-system,"Segoe UI",Roboto,"DejaVu Sans",sans-serif;color:var(--fg);background:var(--bg)}
main{padding:16px 24px 48px;max-width:1900px}
h1{font-size:22px;margin:0 0 8px}h2{font-size:18px;margin:28px 0 10px;border-bottom:2px solid var(--line);padding-bottom:4px}
h3{font-size:15px;margin:0;word-break:break-all}h4{font-size:13px;margin:14px 0 6px;color:#495057}
a{color:#1864ab}
code,pre,.mono{font-family:"DejaVu Sans Mono",Menlo,Consolas,monospace;font-size:12.5px}
header.summary{background:#fff;border:1px solid var(--line);border-left:8px solid var(--pass);padding:14px 18px;border-radius:6px}
header.summary.overall-fail{border-left-color:var(--fail)}
.counts{display:flex;gap:8px;flex-wrap:wrap;margin:8px 0 12px}
.count{border:0;border-radius:5px;padding:6px 12px;color:#fff;font-weight:600;font-size:14px;cursor:pointer}
.count.zero{opacity:.35}
.badge{display:inline-block;border-radius:4px;padding:1px 8px;color:#fff;font-weight:600;font-size:12px;text-transform:uppercase;vertical-align:middle}
.v-pass{background:var(--pass)}.v-fail{background:var(--fail)}.v-improved{background:var(--improved)}.v-missing-golden{background:var(--missing)}.v-error{background:var(--error)}
.dirty{background:#f08c00}.flaky{background:#5f3dc4}.v-none{background:#dee2e6}
table{border-collapse:collapse}
table.info td,table.info th{padding:2px 14px 2px 0;text-align:left;vertical-align:top}table.info th{color:var(--mut);font-weight:500}
table.grid{background:#fff;border:1px solid var(--line);font-size:13px}
table.grid th,table.grid td{border-bottom:1px solid var(--line);padding:4px 10px;text-align:left;vertical-align:top}
table.grid th{background:#f1f3f5;font-weight:600}
table.grid td.num{text-align:right;font-variant-numeric:tabular-nums;font-family:"DejaVu Sans Mono",monospace;font-size:12px}
td.st-fail,td.st-error{color:var(--fail);font-weight:700}td.st-pass{color:var(--pass)}td.st-improved{color:var(--improved);font-weight:700}
.cmd{display:flex;align-items:flex-start;gap:8px;margin:6px 0}
.cmd pre{margin:0;padding:6px 10px;background:#212529;color:#f8f9fa;border-radius:4px;white-space:pre-wrap;word-break:break-all;flex:0 1 auto;user-select:all}
button.copy{font-size:12px;padding:4px 10px;cursor:pointer}
.filterbar{position:sticky;top:0;z-index:5;background:var(--bg);padding:10px 0;border-bottom:1px solid var(--line);display:flex;gap:14px;align-items:center;flex-wrap:wrap}
.filterbar input[type=search]{font-size:14px;padding:5px 8px;width:360px}
.filterbar label{white-space:nowrap}
nav.toc a{margin-right:14px}
section.test{background:#fff;border:1px solid var(--line);border-left:6px solid var(--pass);border-radius:6px;padding:12px 16px;margin:14px 0}
section.test.s-fail{border-left-color:var(--fail)}section.test.s-error{border-left-color:var(--error)}section.test.s-missing-golden{border-left-color:var(--missing)}section.test.s-improved{border-left-color:var(--improved)}
.meta{color:var(--mut);font-size:12.5px;margin:2px 0 6px}
table.overview{width:100%}td.msg{overflow-wrap:anywhere;font-size:12px;color:#495057;min-width:240px}
.message{margin:6px 0;white-space:pre-wrap;overflow-wrap:anywhere;font-family:"DejaVu Sans Mono",monospace;font-size:12.5px}
.warn{background:#fff3bf;border:1px solid #fab005;border-radius:4px;padding:5px 10px;margin:6px 0}
.images{display:flex;gap:14px;flex-wrap:wrap;align-items:flex-start;overflow-x:auto}
figure{margin:0}figcaption{font-size:12px;color:var(--mut);margin-top:2px}
img{image-rendering:pixelated;image-rendering:crisp-edges;max-width:none;display:block;background:repeating-conic-gradient(#ddd 0 25%,#fff 0 50%) 0 0/16px 16px}
.flick{display:inline-grid;cursor:crosshair;outline:1px solid var(--line)}.flick>img{grid-area:1/1}
.flick>img.g{visibility:hidden}.flick:hover>img.g{visibility:visible}
.hm{position:relative;display:inline-block;outline:1px solid var(--line)}
.blk{position:absolute;width:16px;height:16px;outline:2px solid #40c057;outline-offset:0;pointer-events:none}
.noimg{display:inline-block;padding:20px;border:1px dashed var(--fail);color:var(--fail);font-size:12px}
.cols{display:flex;gap:22px;flex-wrap:wrap;align-items:flex-start;margin-top:8px}
dl.metrics{display:grid;grid-template-columns:auto auto;gap:1px 10px;margin:0;font-size:12.5px}dl.metrics dt{color:var(--mut)}dl.metrics dd{margin:0;font-family:"DejaVu Sans Mono",monospace}
.strip{display:flex;gap:4px;align-items:center;overflow-x:auto;margin:4px 0}.strip .lbl{width:78px;flex:none;font-size:12px;color:var(--mut)}
.player{display:flex;gap:10px;align-items:center;flex-wrap:wrap;margin:6px 0}
.trend{font-size:12.5px;margin-top:6px}.moved-txt{color:var(--fail);font-weight:600}
svg.chart{background:#fff;border:1px solid var(--line);border-radius:6px;margin:6px 12px 12px 0;font-family:system-ui,"DejaVu Sans",sans-serif}
svg.chart .ctitle{font-size:14px;font-weight:600}svg.chart .cnote{font-size:11px;fill:#868e96}
svg.chart .plot{fill:#fcfcfd;stroke:#adb5bd}svg.chart .grid{stroke:#eceef0}svg.chart .tick{stroke:#868e96}
svg.chart .tl{font-size:10.5px;fill:#495057}svg.chart .al{font-size:12px;fill:#212529}
svg.chart .pl{font-size:10px;fill:#343a40}svg.chart .legend text{font-size:11.5px;fill:#212529}
svg.chart polyline{fill:none;stroke-width:1.8}svg.chart line.series,svg.chart .legend line{stroke-width:2}
svg.chart .dashed{stroke-dasharray:5 3}
svg.chart .pareto-front{fill:none;stroke:#212529;stroke-width:1.5;stroke-dasharray:6 4}
svg.chart .front-ring{fill:none;stroke:#212529;stroke-width:1.2}
svg.chart circle.point{stroke:#fff;stroke-width:1}svg.chart circle.point:hover{stroke:#000;stroke-width:2}
svg.spark{border:0;margin:0;background:transparent;vertical-align:middle}
svg.spark .sl{stroke:#495057;stroke-width:1.3}svg.spark circle.point{fill:#495057;stroke:none}svg.spark circle.last{fill:#1971c2}
svg.spark line.moved{stroke:#e03131;stroke-dasharray:2 2}svg.spark text.moved{font-size:9.5px;fill:#e03131}
.vstrip{display:inline-flex;gap:1px}.vstrip span{width:6px;height:14px;display:inline-block}
.charts{display:flex;flex-wrap:wrap}
footer{color:var(--mut);font-size:12px;margin-top:30px}
[hidden]{display:none!important}
)CSS";

// Filter (name substring + verdicts), copy buttons, frame players, and the load check that the
// headless test reads back: <body data-images-total data-images-failed data-chart-points ...>.
inline constexpr const char* kJs = R"JS(
(function(){
  'use strict';
  var q=document.getElementById('filter-text');
  var boxes=Array.prototype.slice.call(document.querySelectorAll('.vfilter input'));
  var items=Array.prototype.slice.call(document.querySelectorAll('.filterable'));
  var cnt=document.getElementById('filter-count');
  function apply(){
    var s=(q&&q.value||'').toLowerCase(), on={}, n=0, total=0;
    boxes.forEach(function(b){on[b.value]=b.checked;});
    items.forEach(function(el){
      var ok=el.getAttribute('data-name').toLowerCase().indexOf(s)>=0&&on[el.getAttribute('data-verdict')]!==false;
      el.hidden=!ok;
      if(el.tagName==='SECTION'){total++;if(ok)n++;}
    });
    if(cnt)cnt.textContent=n+' of '+total+' tests shown';
  }
  if(q)q.addEventListener('input',apply);
  boxes.forEach(function(b){b.addEventListener('change',apply);});
  Array.prototype.forEach.call(document.querySelectorAll('button.count'),function(btn){
    btn.addEventListener('click',function(){
      var v=btn.getAttribute('data-verdict'), only=boxes.every(function(b){return b.checked===(b.value===v);});
      boxes.forEach(function(b){b.checked=only||b.value===v;});
      apply();
    });
  });
  var reset=document.getElementById('filter-reset');
  if(reset)reset.addEventListener('click',function(){if(q)q.value='';boxes.forEach(function(b){b.checked=true;});apply();});
  apply();

  Array.prototype.forEach.call(document.querySelectorAll('button.copy'),function(b){
    b.addEventListener('click',function(){
      var code=b.parentElement.querySelector('code'), text=code.textContent;
      function done(){b.textContent='Copied';setTimeout(function(){b.textContent='Copy';},1200);}
      function fallback(){
        try{var r=document.createRange();r.selectNodeContents(code);var sel=window.getSelection();
            sel.removeAllRanges();sel.addRange(r);document.execCommand('copy');done();}catch(e){}
      }
      if(navigator.clipboard&&window.isSecureContext){navigator.clipboard.writeText(text).then(done,fallback);}
      else fallback();
    });
  });

  Array.prototype.forEach.call(document.querySelectorAll('.player'),function(p){
    var ft=(p.getAttribute('data-frames')||'').split(' ').filter(Boolean);
    var fr=(p.getAttribute('data-ref-frames')||'').split(' ').filter(Boolean);
    var it=p.querySelector('img.pt'), ir=p.querySelector('img.pr'), btn=p.querySelector('button');
    var rng=p.querySelector('input'), lab=p.querySelector('.fr');
    var n=Math.max(ft.length,fr.length), i=0, timer=null;
    function show(k){i=(k+n)%n;if(it&&ft.length)it.src=ft[Math.min(i,ft.length-1)];
      if(ir&&fr.length)ir.src=fr[Math.min(i,fr.length-1)];if(rng)rng.value=i;if(lab)lab.textContent='frame '+(i+1)+' / '+n;}
    if(!n)return;
    if(rng){rng.max=n-1;rng.addEventListener('input',function(){show(parseInt(rng.value,10));});}
    if(btn)btn.addEventListener('click',function(){
      if(timer){clearInterval(timer);timer=null;btn.textContent='\u25B6 play';}
      else{timer=setInterval(function(){show(i+1);},1000/12);btn.textContent='\u275A\u275A pause';}
    });
    show(0);
  });

  window.addEventListener('load',function(){
    var imgs=Array.prototype.slice.call(document.images);
    var bad=imgs.filter(function(im){return !(im.complete&&im.naturalWidth>0);});
    var charts=document.querySelectorAll('svg.chart'), declared=0;
    Array.prototype.forEach.call(charts,function(c){declared+=parseInt(c.getAttribute('data-points')||'0',10);});
    var b=document.body;
    b.setAttribute('data-images-total',imgs.length);
    b.setAttribute('data-images-failed',bad.length);
    b.setAttribute('data-images-failed-src',bad.map(function(im){return im.getAttribute('src');}).join(' '));
    b.setAttribute('data-charts',charts.length);
    b.setAttribute('data-chart-points',document.querySelectorAll('svg.chart circle.point').length);
    b.setAttribute('data-chart-points-declared',declared);
    b.setAttribute('data-tests',document.querySelectorAll('section.test').length);
    b.setAttribute('data-check','done');
  });
})();
)JS";

} // namespace iblcheck::report::assets
