// directlab's report pages: sortable tables and the page's own checks (a classic script:
// pages open from disk). DOC (set by the page) says what the body holds.
"use strict";
(function () {
  // A cell's sort key: its number where it starts with one (1.2e-3, 45 %, -inf), else text.
  function key(cell) {
    if (cell.dataset.v !== undefined) return parseFloat(cell.dataset.v);
    const t = cell.textContent.trim();
    const m = /^[-+]?(\d+\.?\d*|\.\d+)(e[-+]?\d+)?/i.exec(t);
    if (m) return parseFloat(m[0]);
    if (/^[-+]?inf/i.test(t)) return t[0] === "-" ? -Infinity : Infinity;
    return t;
  }
  function numeric(v) { return typeof v === "number"; }
  // A click on a header sorts by that column (again: the other way); numbers before text.
  function sortBy(table, col) {
    const body = table.tBodies[0];
    const rows = Array.from(body.rows);
    const asc = table.dataset.col !== String(col) || table.dataset.dir !== "asc";
    rows.sort((a, b) => {
      const x = key(a.cells[col]), y = key(b.cells[col]);
      const c = numeric(x) !== numeric(y) ? (numeric(x) ? -1 : 1) : x < y ? -1 : x > y ? 1 : 0;
      return asc ? c : -c;
    });
    rows.forEach((r) => body.appendChild(r));
    table.dataset.col = String(col); table.dataset.dir = asc ? "asc" : "desc";
  }
  function sortable() {
    document.querySelectorAll("table").forEach((t) => {
      if (!t.tHead || !t.tBodies[0]) return;
      Array.from(t.tHead.rows[0].cells).forEach((th, i) => {
        th.title = "click to sort";
        th.onclick = () => sortBy(t, i);
      });
    });
  }
  // The document's checks: every table sorts, every figure is there and loaded.
  function checks(ok) {
    const tables = Array.from(document.querySelectorAll("#doc table"));
    ok("the report's tables are all here", tables.length === DOC.tables);
    for (const t of tables) {
      const rows = t.tBodies[0] ? t.tBodies[0].rows : [];
      if (rows.length < 2) continue;
      // The first column whose cells are all numbers, sorted both ways.
      const n = rows[0].cells.length;
      for (let c = 0; c < n; c++) {
        if (!Array.from(rows).every((r) => r.cells[c] && numeric(key(r.cells[c])))) continue;
        t.tHead.rows[0].cells[c].click();
        const up = Array.from(t.tBodies[0].rows).map((r) => key(r.cells[c]));
        t.tHead.rows[0].cells[c].click();
        const down = Array.from(t.tBodies[0].rows).map((r) => key(r.cells[c]));
        ok("a click on a header sorts the table",
           up.every((v, i) => i === 0 || up[i - 1] <= v) &&
           down.every((v, i) => i === 0 || down[i - 1] >= v));
        break;
      }
    }
    ok("every plot is inline", document.querySelectorAll("#doc span.plot svg").length === DOC.svgs);
    const imgs = Array.from(document.querySelectorAll("#doc img"));
    ok("every figure is here", imgs.length === DOC.imgs);
    const broken = imgs.filter((i) => !(i.complete && i.naturalWidth > 0)).map((i) => i.alt || i.src);
    ok("every figure loads" + (broken.length ? " (not: " + broken.join(", ") + ")" : ""), broken.length === 0);
  }
  function report(checks) {
    const failed = checks.filter((c) => !c[1]).map((c) => c[0]);
    document.getElementById("selftest").textContent = failed.length === 0
      ? "SELFTEST PASS " + checks.length + " checks"
      : "SELFTEST FAIL " + failed.join("; ");
  }
  window.directlabDoc = { checks: checks, report: report };
  window.addEventListener("error", (e) => {
    document.getElementById("selftest").textContent = "SELFTEST FAIL uncaught: " + e.message;
  });
  window.addEventListener("load", () => {
    sortable();
    // A page with the image viewer runs these checks within its own.
    if (location.hash === "#selftest" && typeof DL === "undefined") {
      const list = [];
      checks((what, cond) => list.push([what, !!cond]));
      report(list);
    }
  });
})();
