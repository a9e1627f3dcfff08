// directlab's report viewer: a classic script (pages open from disk: no modules, no fetch).
// DL (set by the page) holds the images as zlib-compressed RGBE in base64.
"use strict";
(function () {
  const $ = (id) => document.getElementById(id);
  const W = DL.width, H = DL.height;
  const imgs = [];      // Float32Array RGB per image, in DL.images order
  let cur = 1, holdRef = false, view = "image";
  // Layout: one image, side by side with the reference, or a swipe between the two at
  // column `split`. Zoom and pan apply to every canvas alike.
  let layout = "single", split = Math.floor(W / 2), zoom = 1, panX = 0, panY = 0;

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
  // False colour for t in [0, 1]: dark blue, cyan, yellow, red.
  function ramp(t) {
    t = Math.min(1, Math.max(0, t));
    const k = [[0.05, 0.05, 0.35], [0.0, 0.7, 0.9], [1.0, 0.9, 0.1], [0.85, 0.05, 0.05]];
    const x = t * 3, i = Math.min(2, Math.floor(x)), u = x - i;
    return k[i].map((a, c) => 255 * (a + (k[i + 1][c] - a) * u));
  }
  function pixel(view, x, r, i) {
    if (view === "image") {
      const e = exposure();
      return [0, 1, 2].map((c) => 255 * srgb(Math.min(1, Math.max(0, x[i + c] * e))));
    }
    if (view === "relmse") {
      let s = 0;
      for (let c = 0; c < 3; c++) s += (x[i + c] - r[i + c]) ** 2 / (r[i + c] ** 2 + DL.eps);
      // log10 of the pixel's relMSE over the scene's fixed decades.
      const t = (Math.log10(s / 3 + 1e-30) - DL.relmse_lo) / (DL.relmse_hi - DL.relmse_lo);
      return ramp(t);
    }
    let d = 0, m = 0;
    for (let c = 0; c < 3; c++) { d += x[i + c] - r[i + c]; m += r[i + c]; }
    const t = 0.5 + 0.5 * Math.max(-1, Math.min(1, d / (m + DL.eps * 3) / DL.signed_range));
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
  function draw() {
    const show = holdRef ? 0 : cur;
    render($("canvas"), show, layout === "swipe" ? split : undefined);
    $("pane2").style.display = layout === "side" ? "inline-block" : "none";
    if (layout === "side") render($("canvas2"), 0);
    place();
    document.querySelectorAll("#tabs button").forEach((b, i) => b.classList.toggle("on", i === show));
    $("caption").textContent = DL.images[show].title + (view !== "image" ? " — " + view : "") +
      (layout === "side" ? " | reference" : layout === "swipe" ? " / reference (swipe)" : "");
    $("bar").style.display = view === "image" ? "none" : "block";
    $("imgmetrics").textContent = DL.images[show].metrics
      .map((m) => m[0] + " " + (Math.abs(m[1]) >= 1e4 || Math.abs(m[1]) < 1e-2 ? m[1].toExponential(3) : m[1].toPrecision(4)))
      .join("   ");
  }
  function select(i) { if (i >= 0 && i < imgs.length) { cur = i; draw(); } }
  function setView(v) { view = v; draw(); }
  function setLayout(l) { layout = l; draw(); }
  function setZoom(z, cx, cy) {
    // Keep the point under (cx, cy) where it is.
    const nz = Math.min(64, Math.max(1, z));
    panX = cx - (cx - panX) * nz / zoom; panY = cy - (cy - panY) * nz / zoom;
    zoom = nz;
    if (zoom === 1) { panX = 0; panY = 0; }
    place();
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
    // A mid-tone pixel the page writer chose and tone-mapped itself (film::to_srgb8 of the
    // RGBE value): the canvas must show those bytes.
    const p = DL.check.pixel;
    const shown = () => Array.from(at(p)).slice(0, 3);
    const want = () => pixel("image", imgs[1], imgs[0], 3 * p).map(Math.round);
    const a = shown();
    ok("the canvas shows what directlab's tone mapping gives",
       [0, 1, 2].every((c) => Math.abs(a[c] - DL.check.srgb8[c]) <= 1));
    $("ev").value = "1"; draw();
    const b = shown();
    ok("one stop brighter", b[0] > a[0] && [0, 1, 2].every((c) => Math.abs(b[c] - want()[c]) <= 1));
    $("ev").value = "0";
    holdRef = true; draw();
    ok("holding shows the reference", $("caption").textContent.startsWith(DL.images[0].title));
    holdRef = false;
    setView("relmse"); ok("relMSE map", $("bar").style.display === "block");
    setView("signed"); ok("signed error map", $("caption").textContent.includes("signed"));
    setView("image"); select(1);
    setLayout("side");
    const ref0 = pixel("image", imgs[0], imgs[0], 3 * p).map(Math.round);
    const b2 = Array.from($("canvas2").getContext("2d").getImageData(p % W, Math.floor(p / W), 1, 1).data);
    ok("side by side shows the reference beside", $("pane2").style.display !== "none" &&
       [0, 1, 2].every((c) => Math.abs(b2[c] - ref0[c]) <= 1));
    setLayout("swipe"); split = (p % W) + 1; draw();
    const left = shown();
    split = p % W; draw();
    const right = shown();
    ok("the swipe shows the image left of the split and the reference right of it",
       [0, 1, 2].every((c) => Math.abs(left[c] - want()[c]) <= 1 && Math.abs(right[c] - ref0[c]) <= 1));
    setLayout("side"); setZoom(4, 0, 0);
    ok("zoom is shared and nearest-neighbour",
       $("canvas").style.transform === $("canvas2").style.transform &&
       $("canvas").style.transform.includes("scale(4)") &&
       getComputedStyle($("canvas")).imageRendering === "pixelated");
    setZoom(1, 0, 0); setLayout("single");
    ok("the image's metrics are shown", $("imgmetrics").textContent.includes("relMSE"));
    if (document.readyState !== "complete") await new Promise((r) => window.addEventListener("load", r));
    window.directlabDoc.checks(ok);
    window.directlabDoc.report(checks);
  }
  document.addEventListener("keydown", (e) => {
    if (e.key >= "1" && e.key <= "9") select(parseInt(e.key, 10) - 1);
    else if (e.key === "ArrowRight") select((cur + 1) % imgs.length);
    else if (e.key === "ArrowLeft") select((cur + imgs.length - 1) % imgs.length);
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
      const c = $("canvas"); c.width = W; c.height = H;
      DL.images.forEach((im, i) => {
        const b = document.createElement("button");
        b.textContent = (i + 1) + " " + im.title;
        b.onclick = () => select(i);
        $("tabs").appendChild(b);
      });
      $("ev").oninput = draw;
      c.width = W; c.height = H; $("canvas2").width = W; $("canvas2").height = H;
      document.querySelectorAll(".view").forEach((v) => {
        v.addEventListener("wheel", (e) => {
          e.preventDefault();
          const r = v.getBoundingClientRect();
          setZoom(e.deltaY < 0 ? zoom * 1.25 : zoom / 1.25, e.clientX - r.left, e.clientY - r.top);
        });
        let drag = null;
        v.addEventListener("mousedown", (e) => { drag = [e.clientX - panX, e.clientY - panY]; });
        window.addEventListener("mouseup", () => { drag = null; });
        v.addEventListener("mousemove", (e) => {
          if (drag) { panX = e.clientX - drag[0]; panY = e.clientY - drag[1]; place(); return; }
          if (layout === "swipe") {
            const r = $("canvas").getBoundingClientRect();
            split = Math.max(0, Math.min(W, Math.floor((e.clientX - r.left) / r.width * W)));
            draw();
          }
        });
      });
      // A link can open a chosen state: #image=3&layout=side&view=relmse&ev=1.
      const want = new URLSearchParams(location.hash.slice(1));
      if (want.has("image")) cur = Math.min(imgs.length - 1, Math.max(0, parseInt(want.get("image"), 10) - 1 || 0));
      if (["single", "side", "swipe"].includes(want.get("layout"))) layout = want.get("layout");
      if (["image", "relmse", "signed"].includes(want.get("view"))) view = want.get("view");
      if (want.has("ev")) $("ev").value = want.get("ev");
      draw();
      if (location.hash === "#selftest") return selftest();
    })
    .catch((e) => { $("selftest").textContent = "SELFTEST FAIL " + e; });
})();
