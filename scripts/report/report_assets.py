"""The page's inline CSS and JavaScript (no network, no external files)."""

# Magma at 0, 0.25, 0.5, 0.75, 1 (the FLIP maps' colour map) for the colour bar.
MAGMA_STOPS = ("#000004", "#51127c", "#b73779", "#fc8961", "#fcfdbf")

CSS = """
:root { --fg: #1a1a1a; --muted: #666; --line: #d9d9d9; --bg2: #f6f6f6; --accent: #0b5cad; }
* { box-sizing: border-box; }
body { font: 14px/1.45 system-ui, -apple-system, "Segoe UI", "DejaVu Sans", Arial, sans-serif;
       color: var(--fg); margin: 0; padding: 0 28px 40px; background: #fff; }
h1 { font-size: 24px; margin: 22px 0 4px; }
h2 { font-size: 19px; margin: 34px 0 8px; padding-top: 10px; border-top: 2px solid #222; }
h3 { font-size: 16px; margin: 22px 0 6px; }
h4 { font-size: 14px; margin: 14px 0 4px; }
p, li { max-width: 980px; }
a { color: var(--accent); }
code { font-family: "DejaVu Sans Mono", Menlo, Consolas, monospace; font-size: 12px;
       background: var(--bg2); padding: 0 3px; border-radius: 3px; }
.lead { color: #333; font-size: 15px; margin: 2px 0 12px; }
.muted, .note { color: var(--muted); font-size: 12px; }
nav { position: sticky; top: 0; z-index: 5; background: rgba(255,255,255,0.96);
      border-bottom: 1px solid var(--line); padding: 6px 0; margin: 0 -28px; padding-left: 28px; }
nav a { margin-right: 14px; font-size: 13px; text-decoration: none; }
table.meta td { padding: 1px 14px 1px 0; vertical-align: top; }
table.meta td:first-child { color: var(--muted); white-space: nowrap; }
.counts span { margin-right: 10px; }
.sw { display: inline-block; width: 10px; height: 10px; border-radius: 2px; margin-right: 5px;
      vertical-align: baseline; }
.badge { display: inline-block; font-size: 11px; padding: 0 5px; border-radius: 3px;
         margin-left: 4px; white-space: nowrap; }
.st-ok { background: #e3f3e6; color: #17602a; }
.st-nonfinite { background: #fde9d7; color: #8a3b00; }
.st-unsupported { background: #ececec; color: #444; }
.st-unreadable { background: #f8d7da; color: #842029; }
.st-invalid { background: #b3261e; color: #fff; font-weight: 600; }
.b-best { background: #0b5cad; color: #fff; }
.b-noise { background: #e3f3e6; color: #17602a; }
.b-front { background: #fff3c4; color: #6b5200; }
.b-tie { background: #e8e8f4; color: #33336b; border: 1px dashed #8888aa; }
.basis { font-weight: 600; }
.b-update { background: #e3eefa; color: #0b3d75; }
.b-rebuild { background: #b3261e; color: #fff; font-weight: 600; }
.b-stale { background: #fde9d7; color: #8a3b00; font-weight: 600; }
.b-quiet { background: #e3f3e6; color: #17602a; }
table.strip { border-collapse: collapse; font-size: 11px; margin: 6px 0 12px; }
table.strip th, table.strip td { padding: 2px 3px; vertical-align: middle; text-align: center; }
table.strip thead th { color: var(--muted); font-weight: 400; }
table.strip tbody th { text-align: left; font-weight: 400; max-width: 220px; font-size: 12px; }
table.strip td.tmap { padding-left: 12px; border-left: 2px solid var(--line); }
table.strip tr.strip-ref th { font-weight: 600; }
table.strip .badge { white-space: normal; }
table.data.cost th, table.data.sequence-errors th { white-space: normal; min-width: 70px; max-width: 190px;
                                          vertical-align: bottom; }
.card-nums .static { color: #444; }
.card-nums { max-width: 640px; }
.card-nums .headline { font-size: 13px; }
.card-nums .second { color: #333; }
.card-links { font-size: 12px; margin-top: 2px; }
.device-note { display: inline-block; max-width: 980px; background: #fff4e5;
               border-left: 4px solid #e69f00; padding: 2px 8px; }
ul.trend { margin: 2px 0 0; padding-left: 18px; font-size: 12px; }
li.no-effect { margin: 3px 0; }
td.params details summary { font-size: 11px; }
.exposure-bar { display: flex; gap: 10px; align-items: center; flex-wrap: wrap; margin: 6px 0 10px;
                padding: 6px 10px; background: var(--bg2); border-radius: 4px; font-size: 13px; }
.exposure-bar input[type=range] { width: 220px; }
.exposure-bar output { font-variant-numeric: tabular-nums; min-width: 64px; display: inline-block; }
.colorbar { display: inline-flex; align-items: center; gap: 4px; }
.colorbar i { display: inline-block; width: 120px; height: 10px; border: 1px solid #999; }
.cards { display: flex; flex-wrap: wrap; gap: 12px; align-items: flex-start; }
.card { border: 1px solid var(--line); border-top: 4px solid #888; border-radius: 4px;
        padding: 6px 8px 8px; background: #fff; }
.card-title { font-weight: 600; }
.card-params { font-size: 12px; color: #333; min-height: 1.2em; }
.card-nums { font-size: 12px; margin-top: 3px; font-variant-numeric: tabular-nums; }
.pair { display: flex; gap: 6px; margin-top: 4px; }
.pair figure, .refs figure { margin: 0; }
.pair figcaption, .refs figcaption { font-size: 11px; color: var(--muted);
                                     overflow-wrap: anywhere; }
img.px { image-rendering: pixelated; }
img.broken { outline: 2px solid #c00; }
.missing { width: 200px; height: 120px; border: 1px dashed #bbb; color: var(--muted);
           font-size: 11px; padding: 6px; overflow-wrap: anywhere; }
details { margin: 8px 0; }
details summary { cursor: pointer; color: var(--accent); font-size: 13px; }
details .cards { margin-top: 8px; }
.table-wrap { overflow-x: auto; max-width: 100%; border: 1px solid var(--line); }
#run-table th { white-space: normal; min-width: 56px; max-width: 120px; vertical-align: bottom; }
#run-table th:first-child, #run-table td:first-child { position: sticky; left: 0; z-index: 2;
  background: #fff; box-shadow: 1px 0 0 #bbb; white-space: nowrap; }
#run-table th:first-child { z-index: 3; background: #f0f0f0; }
#run-table tr:nth-child(even) td:first-child { background: #fafafa; }
#run-table tr.noise td:first-child { background: #eef8f0; }
#run-table tr.invalid td:first-child { background: #fdecea; }
details.more-params { margin: 0; display: inline; }
details.more-params summary { display: inline; font-size: 11px; }
details.more-params[open] { display: block; }
table.data { border-collapse: collapse; font-size: 12px; font-variant-numeric: tabular-nums; }
table.data th, table.data td { padding: 3px 7px; border-bottom: 1px solid #eee;
                               text-align: left; vertical-align: top; }
table.data th { background: #f0f0f0; position: sticky; top: 0; white-space: nowrap;
                font-weight: 600; border-bottom: 1px solid #bbb; }
table.data td.n { text-align: right; white-space: nowrap; }
table.data tr:nth-child(even) td { background: #fafafa; }
table.data tr.noise td { background: #eef8f0; }
table.data tr.invalid td { background: #fdecea; }
table.sortable th { cursor: pointer; user-select: none; }
table.sortable th::after { content: " \\2195"; color: #aaa; font-weight: 400; }
table.sortable th[aria-sort=ascending]::after { content: " \\25B2"; color: #333; }
table.sortable th[aria-sort=descending]::after { content: " \\25BC"; color: #333; }
td.params { min-width: 150px; max-width: 240px; font-size: 11px; }
td.params b { font-weight: 600; }
td.passes { font-size: 11px; min-width: 240px; max-width: 460px; }
td.passes .pass { white-space: nowrap; }
td.reason { min-width: 90px; }
div.reason { color: #555; font-size: 11px; min-width: 150px; max-width: 240px; }
.pm { color: var(--muted); font-size: 11px; }
td.best { font-weight: 700; background: #fff3c4 !important; }
.filter { margin: 6px 0; font-size: 13px; }
.filter input { width: 260px; padding: 2px 5px; }
figure.plot { margin: 10px 0 18px; }
figure.plot img { max-width: 100%; height: auto; }
figure.plot figcaption { font-size: 12px; color: #444; max-width: 980px; }
ul.skipped { margin: 0; padding-left: 16px; }
footer { margin-top: 40px; font-size: 12px; color: #333; }
footer dt { font-weight: 600; margin-top: 6px; }
footer dd { margin-left: 16px; max-width: 980px; }
.warn { background: #fff4e5; border-left: 4px solid #e69f00; padding: 6px 10px; }
.warn.invalid { background: #fdecea; border-left-color: #b3261e; margin: 12px 0; }
.warn.invalid li { margin: 3px 0; }
code.vmsg { white-space: pre-wrap; overflow-wrap: anywhere; display: inline-block; }
.empty { padding: 30px; background: var(--bg2); border-radius: 6px; font-size: 16px; }
"""

HEAD_JS = """
function gilabImageError(img) {
  img.classList.add("broken");
  console.error("gilab report: cannot load image " + img.getAttribute("src"));
}
"""

BODY_JS = """
(function () {
  "use strict";
  function each(list, fn) { Array.prototype.forEach.call(list, fn); }

  function sortValue(cell, numeric) {
    var v = cell ? cell.getAttribute("data-v") : null;
    if (v === null || v === "") { return null; }
    if (numeric) { var x = parseFloat(v); return isNaN(x) ? null : x; }
    return v.toLowerCase();
  }

  function sortTable(table, index, dir) {
    var head = table.tHead.rows[0];
    var numeric = head.cells[index].getAttribute("data-type") === "num";
    var body = table.tBodies[0];
    var rows = Array.prototype.slice.call(body.rows);
    rows.sort(function (a, b) {
      var x = sortValue(a.cells[index], numeric), y = sortValue(b.cells[index], numeric);
      if (x === null || y === null) { return x === y ? 0 : (x === null ? 1 : -1); }
      return x < y ? -dir : (x > y ? dir : 0);
    });
    each(rows, function (r) { body.appendChild(r); });
    each(head.cells, function (c) { c.removeAttribute("aria-sort"); });
    head.cells[index].setAttribute("aria-sort", dir > 0 ? "ascending" : "descending");
  }

  function columnIndex(table, id) {
    var cells = table.tHead.rows[0].cells;
    for (var i = 0; i < cells.length; i++) {
      if (cells[i].getAttribute("data-col") === id) { return i; }
    }
    return -1;
  }

  each(document.querySelectorAll("table.sortable"), function (table) {
    each(table.tHead.rows[0].cells, function (th, index) {
      th.addEventListener("click", function () {
        var dir = th.getAttribute("aria-sort") === "ascending" ? -1 : 1;
        sortTable(table, index, dir);
        if (table.id === "run-table" && window.history && history.replaceState) {
          history.replaceState(null, "", "#sort=" + th.getAttribute("data-col") + ":" +
                               (dir > 0 ? "asc" : "desc"));
        }
      });
    });
  });

  var runTable = document.getElementById("run-table");
  var match = /^#sort=([A-Za-z0-9_.-]+):(asc|desc)$/.exec(window.location.hash);
  if (runTable && match) {
    var col = columnIndex(runTable, match[1]);
    if (col >= 0) { sortTable(runTable, col, match[2] === "asc" ? 1 : -1); }
  }

  var filter = document.getElementById("run-filter");
  if (runTable && filter) {
    var counter = document.getElementById("run-count");
    filter.addEventListener("input", function () {
      var q = filter.value.trim().toLowerCase(), shown = 0;
      each(runTable.tBodies[0].rows, function (row) {
        var hit = q === "" || row.textContent.toLowerCase().indexOf(q) >= 0;
        row.style.display = hit ? "" : "none";
        if (hit) { shown++; }
      });
      if (counter) { counter.textContent = shown + " of " + runTable.tBodies[0].rows.length; }
    });
  }

  each(document.querySelectorAll("input.exposure"), function (input) {
    var section = input.closest("section");
    var out = input.parentNode.querySelector("output");
    function apply() {
      var stops = parseFloat(input.value) || 0;
      var factor = Math.pow(2, stops / 2.2);
      each(section.querySelectorAll("img.expo"), function (img) {
        img.style.filter = stops === 0 ? "" : "brightness(" + factor.toFixed(4) + ")";
      });
      if (out) { out.textContent = (stops > 0 ? "+" : "") + stops.toFixed(2) + " EV"; }
    }
    input.addEventListener("input", apply);
    var reset = input.parentNode.querySelector("button.reset");
    if (reset) { reset.addEventListener("click", function () { input.value = 0; apply(); }); }
    apply();
  });

  document.body.setAttribute("data-js", "ready");
})();
"""
