(function(){
  'use strict';
  function $(s,r){return (r||document).querySelector(s);}
  function $$(s,r){return Array.prototype.slice.call((r||document).querySelectorAll(s));}
  var CFG=window.IBLCHECK_CFG||{aces:[0,1,0,0,1,1],magma:[]};
  var stats={dataLoaded:0,dataFailed:0,failedKeys:[],viewersReady:0,viewersFailed:0};

  // ---- tabs ----
  var tabs=$$('section.tab'), links=$$('nav.tabs a');
  function showTab(name){
    tabs.forEach(function(t){t.hidden=t.id!=='tab-'+name;});
    links.forEach(function(a){a.classList.toggle('on',a.getAttribute('href')==='#'+name);});
  }
  function route(){
    var h=location.hash.slice(1);
    if(h==='charts'||h==='history'||h==='table'){showTab(h);return;}
    showTab('tests');
    if(/^t-\d+$/.test(h)){var c=document.getElementById(h);if(c){var d=c.closest('details');if(d)d.open=true;
      openCard(c,false);c.scrollIntoView();}}
  }
  window.addEventListener('hashchange',route);

  // ---- filter ----
  var q=$('#filter-text'), boxes=$$('.vfilter input'), cnt=$('#filter-count');
  var items=$$('.filterable');
  function applyFilter(){
    var s=(q&&q.value||'').toLowerCase(), on={}, n=0, total=0;
    boxes.forEach(function(b){on[b.value]=b.checked;});
    items.forEach(function(el){
      var ok=el.getAttribute('data-name').toLowerCase().indexOf(s)>=0&&on[el.getAttribute('data-verdict')]!==false;
      el.hidden=!ok;
      if(el.classList.contains('tile')||el.tagName==='SECTION'){total++;if(ok)n++;}
      if(el.classList.contains('tile')&&!ok){  // a filtered-out tile takes its open card with it
        var c=document.getElementById(el.getAttribute('data-card'));
        if(c&&!c.hidden){c.hidden=true;el.classList.remove('open');}
      }
    });
    if(cnt)cnt.textContent=n+' of '+total+' tests shown';
  }
  if(q)q.addEventListener('input',applyFilter);
  boxes.forEach(function(b){b.addEventListener('change',applyFilter);});
  $$('button.count').forEach(function(btn){
    btn.addEventListener('click',function(){
      var v=btn.getAttribute('data-verdict'), only=boxes.every(function(b){return b.checked===(b.value===v);});
      boxes.forEach(function(b){b.checked=only||b.value===v;});
      showTab('tests');applyFilter();
    });
  });

  // ---- copy buttons ----
  $$('button.copy').forEach(function(b){
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

  // ---- cards: tiles open folded cards; comparison buttons ----
  function openCard(card,toggle){
    var tile=document.querySelector('.tile[data-card="'+card.id+'"]');
    if(card.classList.contains('folded')){
      var open=toggle?card.hidden:true;
      card.hidden=!open;
      if(tile)tile.classList.toggle('open',open);
    }
    if(!card.hidden)return initCard(card);
    return Promise.resolve();
  }
  $$('.tile').forEach(function(t){
    function go(){var c=document.getElementById(t.getAttribute('data-card'));if(c)openCard(c,true);}
    t.addEventListener('click',go);
    t.addEventListener('keydown',function(ev){if(ev.key==='Enter'||ev.key===' '){ev.preventDefault();go();}});
  });
  $$('section.test button.fold').forEach(function(b){
    b.addEventListener('click',function(){var c=b.closest('section.test');openCard(c,true);});
  });
  function showCmp(card,i){
    $$('.cmp-tabs button',card).forEach(function(b){b.classList.toggle('on',b.getAttribute('data-cmp')===String(i));});
    var shown=null;
    $$('.cmp',card).forEach(function(c){var on=c.getAttribute('data-cmp')===String(i);c.hidden=!on;if(on)shown=c;});
    return shown?Promise.all($$('.viewer',shown).map(initViewer)):Promise.resolve();
  }
  function initCard(card){
    var on=$('.cmp-tabs button.on',card);
    if(on)return showCmp(card,on.getAttribute('data-cmp'));
    return Promise.all($$('.viewer',card).map(initViewer));
  }
  $$('.cmp-tabs button').forEach(function(b){
    b.addEventListener('click',function(){showCmp(b.closest('section.test'),b.getAttribute('data-cmp'));});
  });

  // ---- sortable tables: a click on a numeric heading sorts by it, again the other way ----
  $$('table.sortable th[data-sort]').forEach(function(th){
    th.addEventListener('click',function(){
      var table=th.closest('table'), body=table.tBodies[0], col=Array.prototype.indexOf.call(th.parentElement.children,th);
      var dir=th.getAttribute('data-dir')==='asc'?'desc':'asc';
      $$('th[data-sort]',table).forEach(function(h){h.removeAttribute('data-dir');});
      th.setAttribute('data-dir',dir);
      function v(r){var c=r.cells[col],x=c?c.getAttribute('data-v'):null;return x===null||x===''?null:+x;}
      var rows=Array.prototype.slice.call(body.rows);
      rows.sort(function(a,b){var x=v(a),y=v(b);if(x===null)return y===null?0:1;if(y===null)return -1;
        return dir==='asc'?x-y:y-x;});  // empty cells last either way
      rows.forEach(function(r){body.appendChild(r);});
    });
  });

  // ---- float data: data/<key>.js calls iblcheckData(key, meta, base64) ----
  var RAW={}, WAIT={}, DEC={}, H2F=null;
  window.iblcheckData=function(key,meta,b64){
    RAW[key]={meta:meta,b64:b64};stats.dataLoaded++;
    if(WAIT[key])WAIT[key].ok(RAW[key]);
  };
  function script(key){
    if(WAIT[key])return WAIT[key].p;
    var w={};w.p=new Promise(function(ok,bad){w.ok=ok;w.bad=bad;});WAIT[key]=w;
    if(RAW[key]){w.ok(RAW[key]);return w.p;}
    var s=document.createElement('script');
    s.src='data/'+key+'.js';
    s.onerror=function(){stats.dataFailed++;stats.failedKeys.push(key);w.bad(new Error('cannot load data/'+key+'.js'));};
    document.head.appendChild(s);
    return w.p;
  }
  function halfTable(){
    if(H2F)return H2F;
    H2F=new Float32Array(65536);
    for(var h=0;h<65536;h++){
      var s=(h&0x8000)?-1:1, e=(h>>10)&31, m=h&1023;
      H2F[h]=e===0?s*m*Math.pow(2,-24):e===31?(m?NaN:s*Infinity):s*(1+m/1024)*Math.pow(2,e-15);
    }
    return H2F;
  }
  function decoded(key){
    if(!key)return Promise.resolve(null);
    if(DEC[key])return DEC[key];
    DEC[key]=script(key).then(function(d){
      var bin=atob(d.b64), n=bin.length, u=new Uint8Array(n);
      for(var i=0;i<n;i++)u[i]=bin.charCodeAt(i);
      d.b64=null;
      var stream=new Blob([u]).stream().pipeThrough(new DecompressionStream('deflate'));
      return new Response(stream).arrayBuffer().then(function(buf){
        var b=new Uint8Array(buf), m=d.meta, N=m.w*m.h*m.c;
        if(m.enc==='u8')return {meta:m,v:b};
        if(b.length!==2*N)throw new Error('data/'+key+'.js: '+b.length+' bytes, expected '+2*N);
        var f=new Float32Array(N), t=halfTable();
        for(var k=0;k<N;k++)f[k]=t[b[k]|(b[N+k]<<8)];
        return {meta:m,v:f};
      });
    });
    return DEC[key];
  }

  // ---- display: the harness's display transform (ACES fit, clamp, sRGB) after 2^EV ----
  var K=CFG.aces;
  function tone(c){
    var v=((c*c)*K[0]+c*K[1]+K[2])/((c*c)*K[3]+c*K[4]+K[5]);
    v=v<0?0:(v>1?1:v);
    return v<=0.0031308?v*12.92:1.055*Math.pow(v,1/2.4)-0.055;
  }
  function paintImage(cv,img,ev){
    var m=img.meta, w=m.w, h=m.h, c=m.c, s=Math.pow(2,ev), v=img.v;
    cv.width=w;cv.height=h;
    var ctx=cv.getContext('2d'), id=ctx.createImageData(w,h), d=id.data;
    for(var i=0,j=0,o=0;i<w*h;i++,j+=c,o+=4){
      var r=v[j]*s, g=c>2?v[j+1]*s:r, b=c>2?v[j+2]*s:r;
      d[o]=(tone(r)*255+0.5)|0;d[o+1]=(tone(g)*255+0.5)|0;d[o+2]=(tone(b)*255+0.5)|0;d[o+3]=255;
    }
    ctx.putImageData(id,0,0);
  }
  // False colour: one colour per stop of luminance (Rec. 709 weights, linear) against 0.18 at the
  // chosen exposure, -7..+7 stops; black below, white above. Display only.
  var FALSE=[[20,0,60],[50,0,120],[40,40,200],[0,100,230],[0,160,220],[0,200,160],[0,190,60],[110,110,110],
             [140,220,0],[230,230,0],[255,190,0],[255,130,0],[255,60,0],[220,0,60],[255,0,200]];
  window.iblcheckFalseColour=FALSE;
  function stopBand(L,s){
    if(!(L>0))return -1;
    var b=Math.floor(Math.log2(L*s/0.18)+0.5)+7;
    return b<0?-1:(b>14?15:b);
  }
  function luminance(v,j,c){return c>2?0.2126*v[j]+0.7152*v[j+1]+0.0722*v[j+2]:v[j];}
  // Exposure per sphere: each sphere (ids) at the exposure that puts its brightest channel at 1, so
  // no sphere is blown out and a sun's highlight keeps its shape; the background at the image's.
  // Returns the EV of each sphere id.
  function sphereEv(img,ids,base){
    var m=img.meta, c=m.c, v=img.v, n=m.w*m.h, peak={}, out={};
    if(!ids)return out;
    for(var i=0;i<n;i++){
      var id=ids.v[i];if(!id)continue;
      for(var k=0;k<Math.min(c,3);k++)if(!(peak[id]>=v[i*c+k]))peak[id]=v[i*c+k];
    }
    Object.keys(peak).forEach(function(id){out[id]=peak[id]>0?Math.log2(1/peak[id]):base;});
    return out;
  }
  function paintMode(cv,img,ev,mode,ids,sev,auto){
    if(mode==='exp')return paintImage(cv,img,ev);
    var m=img.meta, w=m.w, h=m.h, c=m.c, v=img.v;
    cv.width=w;cv.height=h;
    var ctx=cv.getContext('2d'), id=ctx.createImageData(w,h), d=id.data;
    for(var i=0,j=0,o=0;i<w*h;i++,j+=c,o+=4){
      if(mode==='false'){
        var b=stopBand(luminance(v,j,c),Math.pow(2,ev)), col=b<0?[0,0,0]:(b>14?[255,255,255]:FALSE[b]);
        d[o]=col[0];d[o+1]=col[1];d[o+2]=col[2];
      }else{
        var k=ids?ids.v[i]:0, s=Math.pow(2,(k&&sev[k]!==undefined?sev[k]:auto)+ev-auto);
        var r=v[j]*s, g=c>2?v[j+1]*s:r, bl=c>2?v[j+2]*s:r;
        d[o]=(tone(r)*255+0.5)|0;d[o+1]=(tone(g)*255+0.5)|0;d[o+2]=(tone(bl)*255+0.5)|0;
      }
      d[o+3]=255;
    }
    ctx.putImageData(id,0,0);
  }
  var MAGMA=CFG.magma;
  function paintError(cv,err,scale,mask,tol){
    var m=err.meta, w=m.w, h=m.h, v=err.v, over=0;
    cv.width=w;cv.height=h;
    var ctx=cv.getContext('2d'), id=ctx.createImageData(w,h), d=id.data;
    for(var i=0,o=0;i<w*h;i++,o+=4){
      var x=v[i], k=Math.round(x/scale*255); k=k<0?0:(k>255?255:k);
      if(x>tol)over++;
      if(mask&&x>tol){d[o]=0;d[o+1]=229;d[o+2]=255;}
      else{var f=mask?0.45:1;d[o]=MAGMA[3*k]*f;d[o+1]=MAGMA[3*k+1]*f;d[o+2]=MAGMA[3*k+2]*f;}
      d[o+3]=255;
    }
    ctx.putImageData(id,0,0);
    return over;
  }
  function niceCeil(x){
    if(!(x>0))return 0.01;
    var p=Math.pow(10,Math.floor(Math.log10(x))), f=x/p;
    var r=(f<=1?1:f<=2?2:f<=5?5:10)*p;
    return Math.max(0.01,Math.min(1,r));
  }
  function fmt(x){
    if(x===0)return '0';
    var a=Math.abs(x);
    if(a>=1000)return x.toFixed(0);
    if(a>=1)return x.toPrecision(4).replace(/\.?0+$/,'');
    if(a>=1e-3)return x.toPrecision(3).replace(/(\.\d*?)0+$/,'$1').replace(/\.$/,'');
    return x.toExponential(2);
  }

  // ---- the viewer ----
  function initViewer(v){
    if(v._init)return v._init;
    var ds=v.dataset;
    if(!ds.test){v.setAttribute('data-ready','png');v._init=Promise.resolve();return v._init;}
    v._init=Promise.all([decoded(ds.test),decoded(ds.golden),decoded(ds.error),decoded(ds.ids)]).then(function(r){
      buildViewer(v,r[0],r[1],r[2],r[3]);
      v.setAttribute('data-ready','1');stats.viewersReady++;
    }).catch(function(err){
      v.setAttribute('data-ready','error');stats.viewersFailed++;
      console.error('iblcheck viewer: '+(err&&err.message||err));
    });
    return v._init;
  }

  function buildViewer(v,test,gold,err,ids){
    var ds=v.dataset, w=test.meta.w, h=test.meta.h;
    var spheres=ids&&ids.meta.spheres?ids.meta.spheres:[];
    var bx=ds.bx!==undefined?+ds.bx:-1, by=ds.by!==undefined?+ds.by:-1;
    var st={ev:+(test.meta.auto||0),show:'test',zoom:1,scale:0,mask:false,tol:+(ds.tol||0.05),
            cx:bx>=0?bx+8:w>>1, cy:by>=0?by+8:h>>1, pinned:false, blink:null};
    var imgStage=$('.vimg .stage',v), errStage=$('.verr .stage',v);
    var cvImg=$('canvas.cv-img',v), cvErr=$('canvas.cv-err',v);
    var offT=document.createElement('canvas'), offG=document.createElement('canvas');
    $$('.stage img.png',v).forEach(function(im){im.hidden=true;});
    cvImg.hidden=false;if(cvErr&&err)cvErr.hidden=false;
    var ev=$('input.ev',v), evOut=$('output.evv',v), readout=$('.readout',v);
    var mgT=$('canvas.mg-t',v), mgG=$('canvas.mg-g',v), mgE=$('canvas.mg-e',v), mcap=$('.mcap',v);
    var maskBox=$('input.mask',v), tolIn=$('input.tol',v), maskInfo=$('.maskinfo',v), scaleSel=$('select.escale',v);
    var autoScale=niceCeil(err?err.meta.max:0);
    st.scale=autoScale;
    if(scaleSel){
      var o0=scaleSel.options[0];o0.value=String(autoScale);o0.textContent='auto (0\u2013'+fmt(autoScale)+')';
      scaleSel.value=String(autoScale);
    }
    if(tolIn)tolIn.value=String(st.tol);
    function label(id){var s=spheres[id-1];return s?s.label:'';}
    var autoEv=+(test.meta.auto||0), sevT=null, sevG=null, dmode=$('select.dmode',v), fcl=$('.fclegend',v);
    st.mode='exp';
    function paintImages(){
      if(st.mode==='sphere'&&!sevT){sevT=sphereEv(test,ids,autoEv);sevG=gold?sphereEv(gold,ids,autoEv):{};}
      paintMode(offT,test,st.ev,st.mode,ids,sevT||{},autoEv);
      if(gold)paintMode(offG,gold,st.ev,st.mode,ids,sevG||{},autoEv);
      if(fcl){
        fcl.hidden=st.mode!=='false';
        if(!fcl.firstChild)FALSE.forEach(function(col,b){var sp=document.createElement('span');
          sp.style.background='rgb('+col.join(',')+')';sp.textContent=(b-7>0?'+':'')+(b-7);fcl.appendChild(sp);});
        fcl.title='stops of luminance against 0.18 at '+st.ev.toFixed(1)+' EV; black below -7, white above +7';
      }
      var src=(st.show==='golden'&&gold)?offG:offT;
      cvImg.width=w;cvImg.height=h;cvImg.getContext('2d').drawImage(src,0,0);
      evOut.textContent=(st.ev>0?'+':'')+st.ev.toFixed(1)+' EV'+(Math.abs(st.ev-(test.meta.auto||0))<0.05?' (auto)':'');
      if(ev)ev.value=st.ev;
      $$('button.show',v).forEach(function(b){b.classList.toggle('on',b.getAttribute('data-show')===st.show);});
      paintMag();
    }
    function paintErr(){
      if(!err||!cvErr)return;
      var over=paintError(cvErr,err,st.scale,st.mask,st.tol);
      if(maskInfo)maskInfo.textContent=over+' px ('+(100*over/(w*h)).toFixed(2)+' %) above '+fmt(st.tol);
      var bar=$('.cbar canvas',v);
      if(bar){
        bar.width=256;bar.height=1;var c=bar.getContext('2d'),id=c.createImageData(256,1);
        for(var i=0;i<256;i++){id.data[4*i]=MAGMA[3*i];id.data[4*i+1]=MAGMA[3*i+1];id.data[4*i+2]=MAGMA[3*i+2];id.data[4*i+3]=255;}
        c.putImageData(id,0,0);
        $$('.cbar .tk',v).forEach(function(t,i,a){t.textContent=fmt(st.scale*i/(a.length-1));});
        var tl=$('.cbar .tol',v);if(tl){tl.style.left=Math.min(256,256*st.tol/st.scale)+'px';tl.hidden=st.tol>st.scale;}
      }
      paintMag();
    }
    function paintMag(){
      if(!mgT)return;
      var R=24, P=144, x0=Math.max(0,Math.min(w-R,st.cx-R/2)), y0=Math.max(0,Math.min(h-R,st.cy-R/2)), S=P/R;
      function blit(dst,src){
        if(!dst)return;dst.width=P;dst.height=P;var c=dst.getContext('2d');c.imageSmoothingEnabled=false;
        c.fillStyle='#000';c.fillRect(0,0,P,P);
        if(src)c.drawImage(src,x0,y0,Math.min(R,w),Math.min(R,h),0,0,Math.min(R,w)*S,Math.min(R,h)*S);
        if(bx>=0){c.strokeStyle='#40c057';c.lineWidth=2;c.strokeRect((bx-x0)*S,(by-y0)*S,16*S,16*S);}
      }
      blit(mgT,offT);blit(mgG,gold?offG:null);blit(mgE,err?cvErr:null);
      if(mcap){
        var id=ids?ids.v[Math.min(h-1,st.cy)*w+Math.min(w-1,st.cx)]:0;
        mcap.textContent=S+'\u00d7 '+(st.pinned?'pinned at':'around')+' ('+st.cx+','+st.cy+')'+(id?' on '+label(id):'')+
          (bx>=0?'; green: the worst 16\u00d716 block':'');
      }
    }
    function setZoom(z){
      st.zoom=z;
      [imgStage,errStage].forEach(function(sg){if(!sg)return;sg.style.width=w*z+'px';sg.style.height=h*z+'px';});
      [cvImg,cvErr].forEach(function(c){if(c){c.style.width=w*z+'px';c.style.height=h*z+'px';}});
      $$('.blk',v).forEach(function(b){b.style.left=bx*z+'px';b.style.top=by*z+'px';b.style.width=16*z+'px';b.style.height=16*z+'px';});
      $$('button.z',v).forEach(function(b){b.classList.toggle('on',+b.getAttribute('data-z')===z);});
      v.setAttribute('data-zoom',z);
    }
    function pick(e,stage){
      var r=stage.getBoundingClientRect();
      var x=Math.floor((e.clientX-r.left)/st.zoom), y=Math.floor((e.clientY-r.top)/st.zoom);
      if(x<0||y<0||x>=w||y>=h)return null;return [x,y];
    }
    function rgb(img,x,y){var c=img.meta.c,j=(y*w+x)*c;return c>2?fmt(img.v[j])+' '+fmt(img.v[j+1])+' '+fmt(img.v[j+2]):fmt(img.v[j]);}
    function hover(e,stage){
      var p=pick(e,stage);if(!p)return;
      var x=p[0],y=p[1],id=ids?ids.v[y*w+x]:0,s=spheres[id-1];
      var txt='('+x+','+y+') '+(id?label(id)+(s?' \u00b7 roughness '+fmt(s.roughness)+', metallic '+fmt(s.metallic):''):'background')+
        ' \u00b7 test '+rgb(test,x,y)+(gold?' \u00b7 '+(ds.goldenName||'golden')+' '+rgb(gold,x,y):'')+(err?' \u00b7 FLIP '+fmt(err.v[y*w+x]):'');
      readout.textContent=txt;
      var tip=$('.ptr',stage);
      if(tip){tip.hidden=false;tip.textContent=id?label(id):'background';tip.style.left=(x*st.zoom)+'px';tip.style.top=(y*st.zoom)+'px';}
      if(!st.pinned){st.cx=x;st.cy=y;paintMag();}
    }
    [imgStage,errStage].forEach(function(sg){
      if(!sg)return;
      sg.addEventListener('mousemove',function(e){hover(e,sg);});
      sg.addEventListener('mouseleave',function(){var t=$('.ptr',sg);if(t)t.hidden=true;});
      sg.addEventListener('click',function(e){var p=pick(e,sg);if(!p)return;st.pinned=!st.pinned;st.cx=p[0];st.cy=p[1];paintMag();});
    });
    if(ev)ev.addEventListener('input',function(){st.ev=+ev.value;paintImages();});
    var ba=$('button.ev-auto',v);if(ba)ba.addEventListener('click',function(){st.ev=+(test.meta.auto||0);paintImages();});
    var b0=$('button.ev-0',v);if(b0)b0.addEventListener('click',function(){st.ev=0;paintImages();});
    if(dmode)dmode.addEventListener('change',function(){st.mode=dmode.value;paintImages();});
    $$('button.show',v).forEach(function(b){b.addEventListener('click',function(){st.show=b.getAttribute('data-show');paintImages();});});
    var bl=$('input.blink',v);
    if(bl)bl.addEventListener('change',function(){
      if(st.blink){clearInterval(st.blink);st.blink=null;}
      if(bl.checked&&gold)st.blink=setInterval(function(){st.show=st.show==='test'?'golden':'test';paintImages();},600);
    });
    $$('button.z',v).forEach(function(b){b.addEventListener('click',function(){setZoom(+b.getAttribute('data-z'));});});
    var bw=$('button.worst',v);if(bw)bw.addEventListener('click',function(){st.pinned=false;st.cx=bx>=0?bx+8:w>>1;st.cy=by>=0?by+8:h>>1;paintMag();});
    if(scaleSel)scaleSel.addEventListener('change',function(){st.scale=+scaleSel.value;paintErr();});
    if(maskBox)maskBox.addEventListener('change',function(){st.mask=maskBox.checked;paintErr();});
    if(tolIn)tolIn.addEventListener('input',function(){var t=+tolIn.value;if(t>0){st.tol=t;paintErr();}});
    // Readable by default: the largest whole zoom (at most 4x) that fits beside nothing else.
    var avail=Math.max(200,Math.min(v.clientWidth||1100,1120)-10);
    setZoom(Math.max(1,Math.min(4,Math.floor(avail/w))));
    paintImages();paintErr();
  }

  // ---- temporal players ----
  $$('.player').forEach(function(p){
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

  applyFilter();
  route();
  // Cards shown from the start (what needs a look) get their viewers now.
  var startup=$$('section.test').filter(function(c){return !c.hidden;}).map(initCard);

  // ---- the load check tests/test_report.cpp reads back ----
  window.addEventListener('load',function(){
    Promise.all(startup).then(function(){
      var imgs=$$('img').filter(function(im){return im.getAttribute('src');});
      var bad=imgs.filter(function(im){return !(im.complete&&im.naturalWidth>0);});
      var charts=$$('svg.chart'), declared=0;
      charts.forEach(function(c){declared+=parseInt(c.getAttribute('data-points')||'0',10);});
      var b=document.body;
      b.setAttribute('data-images-total',imgs.length);
      b.setAttribute('data-images-failed',bad.length);
      b.setAttribute('data-images-failed-src',bad.map(function(im){return im.getAttribute('src');}).join(' '));
      b.setAttribute('data-charts',charts.length);
      b.setAttribute('data-chart-points',$$('svg.chart .point').length);
      b.setAttribute('data-chart-points-declared',declared);
      b.setAttribute('data-tests',$$('section.test').length);
      b.setAttribute('data-data-loaded',stats.dataLoaded);
      b.setAttribute('data-data-failed',stats.dataFailed);
      b.setAttribute('data-data-failed-keys',stats.failedKeys.join(' '));
      b.setAttribute('data-viewers-ready',stats.viewersReady);
      b.setAttribute('data-viewers-failed',stats.viewersFailed);
      b.setAttribute('data-check','done');
    });
  });
  window.iblcheckStats=stats;
})();
