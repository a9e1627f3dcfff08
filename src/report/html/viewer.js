// directlab's report viewer: a classic script (pages open from disk: no modules, no fetch).
// DL (set by the page) holds the images as zlib-compressed RGBE in base64.
"use strict";
(function () {
  const $ = (id) => document.getElementById(id);
  const W = DL.width, H = DL.height, K = DL.factor;
  const imgs = [];      // Float32Array RGB per image, in DL.images order
  let cur = 1, holdRef = false, view = "image", selftesting = false;
  // Layout: one image, side by side with the reference, or a swipe between the two at
  // column `split`. Zoom and pan apply to every canvas alike.
  let layout = "single", split = Math.floor(W / 2), zoom = 1, panX = 0, panY = 0;
  let probed = null;    // the film pixel under the cursor, [x, y]

  async function inflate(b64) {
    const bin = Uint8Array.from(atob(b64), (c) => c.charCodeAt(0));
    const s = new Blob([bin]).stream().pipeThrough(new DecompressionStream("deflate"));
    return new Uint8Array(await new Response(s).arrayBuffer());
  }
  function fromRgbe(b) {
    const f = new Float32Array((b.length / 4) * 3);
    for (let i = 0, j = 0; i < b.length; i += 4, j += 3) {
      if (b[i + 3] === 0) continue;
      const s = Math.pow(2, b[i + 3] - 136);
      f[j] = (b[i] + 0.5) * s; f[j + 1] = (b[i + 1] + 0.5) * s; f[j + 2] = (b[i + 2] + 0.5) * s;
    }
    return f;
  }
  const srgb = (v) => (v <= 0.0031308 ? 12.92 * v : 1.055 * Math.pow(v, 1 / 2.4) - 0.055);
  function exposure() { return Math.pow(2, parseFloat($("ev").value)) * DL.exposure; }
  function fmt(v) {
    if (v === null || v === undefined) return "n/a";
    if (v === 0) return "0";
    if (!isFinite(v)) return String(v);
    return Math.abs(v) >= 1e4 || Math.abs(v) < 1e-3 ? v.toExponential(3) : v.toPrecision(4);
  }
  // False colour for t in [0, 1]: dark blue, cyan, yellow, red.
  const RAMP = [[0.05, 0.05, 0.35], [0.0, 0.7, 0.9], [1.0, 0.9, 0.1], [0.85, 0.05, 0.05]];
  function ramp(t) {
    t = Math.min(1, Math.max(0, t));
    const x = t * 3, i = Math.min(2, Math.floor(x)), u = x - i;
    return RAMP[i].map((a, c) => 255 * (a + (RAMP[i + 1][c] - a) * u));
  }
  // A pixel's error against the reference: relMSE (mean over channels, as the map) and the
  // signed relative error of the channel sum (as the signed map).
  function errors(x, r, i) {
    let s = 0, d = 0, m = 0;
    for (let c = 0; c < 3; c++) {
      s += (x[i + c] - r[i + c]) ** 2 / (r[i + c] ** 2 + DL.eps);
      d += x[i + c] - r[i + c]; m += r[i + c];
    }
    return { relmse: s / 3, signed: d / (m + DL.eps * 3) };
  }
  function pixel(view, x, r, i) {
    if (view === "image") {
      const e = exposure();
      return [0, 1, 2].map((c) => 255 * srgb(Math.min(1, Math.max(0, x[i + c] * e))));
    }
    const err = errors(x, r, i);
    if (view === "relmse") {
      // log10 of the pixel's relMSE over the scene's fixed decades.
      return ramp((Math.log10(err.relmse + 1e-30) - DL.relmse_lo) / (DL.relmse_hi - DL.relmse_lo));
    }
    const t = 0.5 + 0.5 * Math.max(-1, Math.min(1, err.signed / DL.signed_range));
    return t < 0.5 ? [255 * 2 * t, 255 * 2 * t, 255] : [255, 255 * 2 * (1 - t), 255 * 2 * (1 - t)];
  }
  function render(canvas, show, splitAt) {
    const x = imgs[show], r = imgs[0];
    const ctx = canvas.getContext("2d");
    const out = ctx.createImageData(W, H);
    const v = show === 0 && view !== "image" ? "image" : view;
    for (let p = 0; p < W * H; p++) {
      // In a swipe, the columns right of the split show the reference.
      const ref = splitAt !== undefined && p % W >= splitAt;
      const c = ref ? pixel("image", r, r, 3 * p) : pixel(v, x, r, 3 * p);
      out.data[4 * p] = c[0]; out.data[4 * p + 1] = c[1]; out.data[4 * p + 2] = c[2];
      out.data[4 * p + 3] = 255;
    }
    ctx.putImageData(out, 0, 0);
  }
  function place() {
    const t = "translate(" + panX + "px," + panY + "px) scale(" + zoom + ")";
    document.querySelectorAll(".view canvas").forEach((c) => { c.style.transform = t; });
  }
  // Pane widths: the film at its display scale, narrowed so that side by side fits the
  // window's width (then the panes sit in one row).
  function fit() {
    const panes = layout === "side" ? 2 : 1;
    const avail = $("views").clientWidth || document.documentElement.clientWidth;
    const w = Math.max(64, Math.floor(Math.min(W * DL.scale, (avail - 8 * (panes - 1)) / panes - 2)));
    document.querySelectorAll(".view").forEach((v) => { v.style.width = w + "px"; });
  }
  // The colour bar of an error view, with its numbers.
  function legend() {
    $("legend").style.display = view === "image" ? "none" : "block";
    if (view === "image") return;
    const ticks = [];
    if (view === "relmse") {
      $("bartitle").textContent = "relMSE per pixel (log scale, decades)";
      $("bar").style.background = "linear-gradient(90deg, " +
        RAMP.map((k) => "rgb(" + k.map((v) => Math.round(255 * v)).join(",") + ")").join(", ") + ")";
      for (let d = DL.relmse_lo; d <= DL.relmse_hi; d++)
        ticks.push([(d - DL.relmse_lo) / (DL.relmse_hi - DL.relmse_lo), "1e" + d]);
    } else {
      $("bartitle").textContent = "signed relative error of the pixel (blue: too dark, red: too bright)";
      $("bar").style.background = "linear-gradient(90deg, #0000ff, #ffffff, #ff0000)";
      for (const f of [-1, -0.5, 0, 0.5, 1])
        ticks.push([0.5 + 0.5 * f, (f > 0 ? "+" : "") + Math.round(100 * f * DL.signed_range) + " %"]);
    }
    $("ticks").innerHTML = "";
    for (const [at, label] of ticks) {
      const s = document.createElement("span");
      s.style.left = (100 * at) + "%"; s.textContent = label;
      $("ticks").appendChild(s);
    }
  }
  // The state a link carries.
  function stateHash() {
    return "image=" + (cur + 1) + "&layout=" + layout + "&view=" + view + "&ev=" + $("ev").value +
      (zoom !== 1 ? "&zoom=" + zoom : "");
  }
  function applyHash(hash) {
    const want = new URLSearchParams(hash.replace(/^#/, ""));
    if (want.has("image")) cur = Math.min(imgs.length - 1, Math.max(0, parseInt(want.get("image"), 10) - 1 || 0));
    if (["single", "side", "swipe"].includes(want.get("layout"))) layout = want.get("layout");
    if (["image", "relmse", "signed"].includes(want.get("view"))) view = want.get("view");
    if (want.has("ev") && isFinite(parseFloat(want.get("ev")))) $("ev").value = want.get("ev");
    if (want.has("zoom")) zoom = Math.min(64, Math.max(1, parseFloat(want.get("zoom")) || 1));
    return want.has("selftest");
  }
  function writeHash() {
    const h = "#" + (selftesting ? "selftest&" : "") + stateHash();
    if (location.hash === h) return;
    try { history.replaceState(null, "", h); } catch (e) { location.replace(h); }
  }
  // What the cursor reads: the film pixel (its block of the EXR when shown box-averaged),
  // the image's and the reference's RGB and luminance, and the pixel's errors.
  function probe(px, py) {
    if (px < 0 || py < 0 || px >= W || py >= H) return "";
    const show = holdRef ? 0 : cur, x = imgs[show], r = imgs[0], i = 3 * (py * W + px);
    const rgb = (a) => [0, 1, 2].map((c) => fmt(a[i + c])).join(" ");
    const lum = (a) => fmt(0.2126 * a[i] + 0.7152 * a[i + 1] + 0.0722 * a[i + 2]);
    const at = K > 1
      ? "pixels " + px * K + "-" + (px * K + K - 1) + ", " + py * K + "-" + (py * K + K - 1) + " (mean)"
      : "pixel " + px + ", " + py;
    const e = errors(x, r, i);
    return at + "\nimage      RGB " + rgb(x) + "   Y " + lum(x) +
      "\nreference  RGB " + rgb(r) + "   Y " + lum(r) +
      "\nerror      relMSE " + fmt(e.relmse) + "   signed " + (100 * e.signed).toFixed(2) + " %";
  }
  function showProbe() { $("probe").textContent = probed ? probe(probed[0], probed[1]) : ""; }
  function draw() {
    const show = holdRef ? 0 : cur;
    fit();
    render($("canvas"), show, layout === "swipe" ? split : undefined);
    $("pane2").style.display = layout === "side" ? "block" : "none";
    if (layout === "side") render($("canvas2"), 0);
    place();
    document.querySelectorAll("#tabs button").forEach((b, i) => b.classList.toggle("on", i === show));
    $("picker").value = String(show);
    $("caption").textContent = DL.images[show].title + (view !== "image" ? " — " + view : "") +
      (layout === "side" ? " | reference" : layout === "swipe" ? " / reference (swipe)" : "");
    const ev = parseFloat($("ev").value);
    $("evtext").textContent = (ev >= 0 ? "+" : "") + ev.toFixed(2) + " stops, radiance x " + fmt(exposure());
    legend();
    showProbe();
    $("imgmetrics").textContent = DL.images[show].metrics.map((m) => m[0] + " " + fmt(m[1])).join("   ");
    writeHash();
  }
  function select(i) { if (i >= 0 && i < imgs.length) { cur = i; draw(); } }
  function step(d) { select((cur + d + imgs.length) % imgs.length); }
  function setView(v) { view = v; draw(); }
  function setLayout(l) { layout = l; draw(); }
  function setZoom(z, cx, cy) {
    // Keep the point under (cx, cy) where it is.
    const nz = Math.min(64, Math.max(1, z));
    panX = cx - (cx - panX) * nz / zoom; panY = cy - (cy - panY) * nz / zoom;
    zoom = nz;
    if (zoom === 1) { panX = 0; panY = 0; }
    place();
    writeHash();
  }
  // The film pixel under a mouse position, from the canvas's on-screen box (zoom and pan
  // included).
  function under(canvas, e) {
    const r = canvas.getBoundingClientRect();
    return [Math.floor((e.clientX - r.left) / r.width * W), Math.floor((e.clientY - r.top) / r.height * H)];
  }

  async function selftest() {
    const checks = [];
    const ok = (what, cond) => checks.push([what, !!cond]);
    const at = (p) => $("canvas").getContext("2d").getImageData(p % W, Math.floor(p / W), 1, 1).data;
    ok("images decoded", imgs.length === DL.images.length && imgs[0].length === W * H * 3);
    select(1);
    ok("switching shows the second image", $("caption").textContent.startsWith(DL.images[1].title));
    document.dispatchEvent(new KeyboardEvent("keydown", { key: "ArrowLeft" }));
    ok("the left arrow goes back to the reference", $("caption").textContent.startsWith(DL.images[0].title));
    document.dispatchEvent(new KeyboardEvent("keydown", { key: "ArrowRight" }));
    ok("the right arrow goes forward", $("caption").textContent.startsWith(DL.images[1].title));
    const last = imgs.length - 1;
    $("picker").value = String(last); $("picker").dispatchEvent(new Event("change"));
    ok("the picker reaches every image (" + imgs.length + ")",
       $("picker").options.length === imgs.length && $("caption").textContent.startsWith(DL.images[last].title));
    $("next").click();
    ok("next after the last is the reference", $("caption").textContent.startsWith(DL.images[0].title));
    select(1);
    // A mid-tone pixel the page writer chose and tone-mapped itself (film::to_srgb8 of the
    // RGBE value): the canvas must show those bytes.
    const p = DL.check.pixel, px = p % W, py = Math.floor(p / W);
    const shown = () => Array.from(at(p)).slice(0, 3);
    const want = () => pixel("image", imgs[1], imgs[0], 3 * p).map(Math.round);
    const a = shown();
    ok("the canvas shows what directlab's tone mapping gives",
       [0, 1, 2].every((c) => Math.abs(a[c] - DL.check.srgb8[c]) <= 1));
    $("ev").value = "1"; draw();
    const b = shown();
    ok("one stop brighter", b[0] > a[0] && [0, 1, 2].every((c) => Math.abs(b[c] - want()[c]) <= 1));
    ok("the exposure shows its number", $("evtext").textContent.startsWith("+1.00 stops"));
    ok("the address follows the view", location.hash === "#selftest&" + stateHash() &&
       location.hash.includes("image=2") && location.hash.includes("ev=1"));
    $("ev").value = "0";
    holdRef = true; draw();
    ok("holding shows the reference", $("caption").textContent.startsWith(DL.images[0].title));
    holdRef = false;
    setView("relmse");
    const decades = DL.relmse_hi - DL.relmse_lo + 1;
    ok("relMSE map with numbers on its colour bar", $("legend").style.display === "block" &&
       $("ticks").children.length === decades && $("ticks").textContent.includes("1e" + DL.relmse_hi));
    setView("signed");
    ok("signed error map with numbers on its colour bar", $("caption").textContent.includes("signed") &&
       $("ticks").textContent.includes("+100 %") && $("ticks").textContent.includes("-100 %"));
    setView("image"); select(1);
    // The pixel under the cursor: move the mouse onto the check pixel's centre.
    const box = $("canvas").getBoundingClientRect();
    $("pane1").dispatchEvent(new MouseEvent("mousemove", {
      clientX: box.left + (px + 0.5) * box.width / W, clientY: box.top + (py + 0.5) * box.height / H,
      bubbles: true }));
    const text = $("probe").textContent, i = 3 * p;
    const y = 0.2126 * imgs[1][i] + 0.7152 * imgs[1][i + 1] + 0.0722 * imgs[1][i + 2];
    ok("the cursor reads the pixel's values", text.includes((K > 1 ? "pixels " + px * K : "pixel " + px) + "") &&
       text.includes("RGB " + fmt(imgs[1][i]) + " " + fmt(imgs[1][i + 1])) && text.includes("Y " + fmt(y)) &&
       text.includes("reference  RGB " + fmt(imgs[0][i])) &&
       text.includes("relMSE " + fmt(errors(imgs[1], imgs[0], i).relmse)));
    setLayout("side");
    const ref0 = pixel("image", imgs[0], imgs[0], 3 * p).map(Math.round);
    const b2 = Array.from($("canvas2").getContext("2d").getImageData(px, py, 1, 1).data);
    ok("side by side shows the reference beside", $("pane2").style.display !== "none" &&
       [0, 1, 2].every((c) => Math.abs(b2[c] - ref0[c]) <= 1));
    const r1 = $("pane1").getBoundingClientRect(), r2 = $("pane2").getBoundingClientRect();
    ok("side by side is one row in a " + window.innerWidth + "-pixel window",
       Math.abs(r1.top - r2.top) < 1 && r2.left >= r1.right && r2.right <= window.innerWidth);
    setLayout("swipe"); split = px + 1; draw();
    const left = shown();
    split = px; draw();
    const right = shown();
    ok("the swipe shows the image left of the split and the reference right of it",
       [0, 1, 2].every((c) => Math.abs(left[c] - want()[c]) <= 1 && Math.abs(right[c] - ref0[c]) <= 1));
    setLayout("side"); setZoom(4, 0, 0);
    ok("zoom is shared and nearest-neighbour",
       $("canvas").style.transform === $("canvas2").style.transform &&
       $("canvas").style.transform.includes("scale(4)") &&
       getComputedStyle($("canvas")).imageRendering === "pixelated");
    setZoom(1, 0, 0); setLayout("single");
    const h = stateHash();
    select(0); setView("relmse");
    applyHash(h); draw();
    ok("a link restores the view", stateHash() === h);
    ok("the image's metrics are shown", $("imgmetrics").textContent.includes("relMSE"));
    if (document.readyState !== "complete") await new Promise((r) => window.addEventListener("load", r));
    window.directlabDoc.checks(ok);
    window.directlabDoc.report(checks);
  }
  document.addEventListener("keydown", (e) => {
    if (e.target && e.target.tagName === "SELECT") return;
    if (e.key >= "1" && e.key <= "9") select(parseInt(e.key, 10) - 1);
    else if (e.key === "ArrowRight" || e.key === "n") step(1);
    else if (e.key === "ArrowLeft" || e.key === "p") step(-1);
    else if (e.key === "r" && !holdRef) { holdRef = true; draw(); }
    else if (e.key === "e") setView(view === "relmse" ? "image" : "relmse");
    else if (e.key === "s") setView(view === "signed" ? "image" : "signed");
    else if (e.key === "?") $("help").classList.toggle("on");
    else if (e.key === "v") setLayout({ single: "side", side: "swipe", swipe: "single" }[layout]);
    else if (e.key === "+" || e.key === "=") setZoom(zoom * 2, 0, 0);
    else if (e.key === "-") setZoom(zoom / 2, 0, 0);
    else if (e.key === "0") setZoom(1, 0, 0);
  });
  document.addEventListener("keyup", (e) => { if (e.key === "r") { holdRef = false; draw(); } });

  Promise.all(DL.images.map((im) => inflate(im.data).then(fromRgbe)))
    .then((all) => {
      imgs.push(...all);
      $("canvas").width = W; $("canvas").height = H; $("canvas2").width = W; $("canvas2").height = H;
      // Tabs for the images keys 1-9 reach; the picker lists every image by group.
      DL.images.slice(0, 9).forEach((im, i) => {
        const b = document.createElement("button");
        b.textContent = (i + 1) + " " + im.title;
        b.onclick = () => select(i);
        $("tabs").appendChild(b);
      });
      let group = null;
      DL.images.forEach((im, i) => {
        if (!group || group.label !== im.group) {
          group = document.createElement("optgroup"); group.label = im.group;
          $("picker").appendChild(group);
        }
        const o = document.createElement("option");
        o.value = String(i); o.textContent = (i + 1) + " " + im.title;
        group.appendChild(o);
      });
      $("picker").onchange = () => { select(parseInt($("picker").value, 10)); $("picker").blur(); };
      $("prev").onclick = () => step(-1);
      $("next").onclick = () => step(1);
      $("ev").oninput = draw;
      window.addEventListener("resize", fit);
      document.querySelectorAll(".view").forEach((v) => {
        v.addEventListener("wheel", (e) => {
          e.preventDefault();
          const r = v.getBoundingClientRect();
          setZoom(e.deltaY < 0 ? zoom * 1.25 : zoom / 1.25, e.clientX - r.left, e.clientY - r.top);
        });
        let drag = null;
        v.addEventListener("mousedown", (e) => { drag = [e.clientX - panX, e.clientY - panY]; });
        window.addEventListener("mouseup", () => { drag = null; });
        v.addEventListener("mouseleave", () => { probed = null; showProbe(); });
        v.addEventListener("mousemove", (e) => {
          if (drag) { panX = e.clientX - drag[0]; panY = e.clientY - drag[1]; place(); return; }
          probed = under(v.querySelector("canvas"), e);
          if (layout === "swipe") { split = Math.max(0, Math.min(W, probed[0])); draw(); }
          else showProbe();
        });
      });
      // A link can open a chosen state: #image=3&layout=side&view=relmse&ev=1.
      selftesting = applyHash(location.hash);
      draw();
      place();
      if (selftesting) return selftest();
    })
    .catch((e) => { $("selftest").textContent = "SELFTEST FAIL " + e; });
})();
