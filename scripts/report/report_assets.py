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
table.data.study td.tie { background: #fff9e0 !important; }
table.data.study td.comp { background: #fde8e8 !important; text-decoration: line-through; }
table.data.study td.flag { color: #b3261e; font-weight: 600; }
table.data.study tr.winners td { border-top: 1px solid #ccc; font-size: 11px; }
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
.rank { font-size: 12px; color: var(--muted); margin-left: 6px; font-weight: 400; }
.noisy { color: #b3261e; font-size: 11px; white-space: nowrap; font-weight: 600; }
caption.device-line { caption-side: top; text-align: left; font-size: 12px; color: #444;
                      padding: 2px 0; }
p.device-line { font-size: 12px; color: #444; margin: 4px 0; }
.no-full-map { max-width: 640px; }
.inspector-note { font-size: 13px; }
img.inspectable { cursor: zoom-in; }
.inspector { position: fixed; inset: 12px; z-index: 20; background: #1b1b1b; color: #eee;
             border-radius: 6px; box-shadow: 0 4px 30px rgba(0,0,0,0.5); display: flex;
             flex-direction: column; font-size: 13px; }
.inspector[hidden] { display: none; }
.inspector a { color: #9cc8ff; }
.ins-bar { display: flex; flex-wrap: wrap; gap: 8px; align-items: center; padding: 6px 10px;
           border-bottom: 1px solid #444; }
.ins-bar button { font: inherit; font-size: 12px; background: #333; color: #eee;
                  border: 1px solid #555; border-radius: 3px; padding: 1px 7px; cursor: pointer; }
.ins-bar button.on { background: #0b5cad; border-color: #0b5cad; }
.ins-layers { display: inline-flex; flex-wrap: wrap; gap: 4px; }
.ins-factor { display: inline-block; min-width: 36px; text-align: center; }
.ins-close { margin-left: auto; }
.ins-view { flex: 1; overflow: auto; background: repeating-conic-gradient(#2a2a2a 0% 25%,
            #222 0% 50%) 0 0 / 16px 16px; display: flex; }
.ins-view img { image-rendering: crisp-edges; image-rendering: pixelated; margin: auto;
                cursor: crosshair; flex: none; }
.ins-status { padding: 5px 10px; border-top: 1px solid #444; font-family: "DejaVu Sans Mono",
              Menlo, Consolas, monospace; font-size: 12px; min-height: 3.2em; }
.ins-more { color: #bbb; }
.ins-help { padding: 3px 10px 6px; color: #aaa; font-size: 11px; }
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

# The image inspector (report_inspect.py, docs/report.md "Image inspector"): a click on an image
# with data-ig (its group) and data-il (its layer) opens the overlay #inspector; keys flip the
# layers and zoom (nearest neighbour), the cursor shows the linear values embedded in
# #gilab-inspector. "#inspector-selftest[:x,y]" drives it and writes what it saw into
# #inspector-selftest-result (read by tests/report/test_report.py).
INSPECTOR_JS = """
(function () {
  "use strict";
  var box = document.getElementById("inspector");
  var dataNode = document.getElementById("gilab-inspector");
  if (!box || !dataNode) { return; }
  var data = JSON.parse(dataNode.textContent);
  var img = box.querySelector(".ins-img"), view = box.querySelector(".ins-view");
  var state = { group: null, layers: [], layer: 0, zoom: 1, w: 0, h: 0, x: -1, y: -1,
                section: null, opener: null };
  var decoded = {};
  var ZOOMS = [1, 2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64];

  function half(bits) {
    var sign = (bits & 0x8000) ? -1 : 1, e = (bits >> 10) & 0x1f, f = bits & 0x3ff;
    if (e === 0) { return sign * f * Math.pow(2, -24); }
    if (e === 31) { return f ? NaN : sign * Infinity; }
    return sign * (1 + f / 1024) * Math.pow(2, e - 15);
  }

  function linear(id) {
    if (!id || !data.images[id]) { return null; }
    if (decoded[id]) { return decoded[id]; }
    var entry = data.images[id], bin = atob(entry.b64), bytes = new Uint8Array(bin.length);
    for (var i = 0; i < bin.length; i++) { bytes[i] = bin.charCodeAt(i); }
    var view = new DataView(bytes.buffer), count = entry.w * entry.h * 3;
    var values = new Float64Array(count);
    for (i = 0; i < count; i++) {
      values[i] = entry.fmt === "f32" ? view.getFloat32(4 * i, true)
                                      : half(view.getUint16(2 * i, true));
    }
    decoded[id] = { w: entry.w, h: entry.h, v: values };
    return decoded[id];
  }

  function rgbAt(id, x, y) {
    var lin = linear(id);
    if (!lin || x < 0 || y < 0 || x >= lin.w || y >= lin.h) { return null; }
    var i = 3 * (y * lin.w + x);
    return [lin.v[i], lin.v[i + 1], lin.v[i + 2]];
  }

  function luma(rgb) { return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]; }
  function fmt(v) { return isFinite(v) ? Number(v).toPrecision(4) : String(v); }
  function fmtRgb(rgb) { return rgb.map(fmt).join(" "); }

  // The value of a layer at (x, y): [text, numbers] (numbers null when the layer has none).
  function valueOf(layer, x, y) {
    if (layer.kind === "relerr") {
      var a = rgbAt(layer.a, x, y), b = rgbAt(layer.b, x, y);
      if (!a || !b) { return ["no value", null]; }
      var e = Math.abs(luma(a) - luma(b)) / layer.mean;
      return ["|\u0394Y| / mean Y = " + fmt(e), [e]];
    }
    if (layer.kind === "map") {
      return ["colour only (the map's values are not stored)", null];
    }
    var rgb = rgbAt(layer.lin, x, y);
    if (!rgb) { return ["no linear values" + (layer.why ? ": " + layer.why : ""), null]; }
    return ["RGB " + fmtRgb(rgb) + " (linear)", rgb];
  }

  function firstLayer(predicate) {
    for (var i = 0; i < state.layers.length; i++) {
      if (predicate(state.layers[i])) { return state.layers[i]; }
    }
    return null;
  }

  function show() {
    var x = state.x, y = state.y, layer = state.layers[state.layer];
    var pos = box.querySelector(".ins-pos"), out = box.querySelector(".ins-value");
    var more = box.querySelector(".ins-more");
    if (x < 0 || y < 0 || x >= state.w || y >= state.h) {
      pos.textContent = "move the cursor over the image";
      out.textContent = ""; more.textContent = ""; out.removeAttribute("data-v");
      return;
    }
    var value = valueOf(layer, x, y);
    pos.textContent = "pixel (" + x + ", " + y + ")";
    out.textContent = layer.name + ": " + value[0];
    out.setAttribute("data-v", value[1] ? value[1].join(" ") : "");
    var others = [];
    state.layers.forEach(function (other, i) {
      if (i !== state.layer && other.kind === "image" && other.lin) {
        var rgb = rgbAt(other.lin, x, y);
        if (rgb) { others.push(other.name + ": " + fmtRgb(rgb)); }
      }
    });
    more.textContent = others.join(" \u00b7 ");
  }

  function exposure() {
    var input = state.section ? state.section.querySelector("input.exposure") : null;
    var stops = input ? parseFloat(input.value) || 0 : 0;
    return stops === 0 ? "" : "brightness(" + Math.pow(2, stops / 2.2).toFixed(4) + ")";
  }

  function setLayer(index) {
    var n = state.layers.length;
    state.layer = ((index % n) + n) % n;
    var layer = state.layers[state.layer];
    img.src = layer.src;
    img.alt = layer.name;
    img.style.filter = layer.expo ? exposure() : "";
    var file = box.querySelector(".ins-file");
    file.href = layer.src;
    var buttons = box.querySelectorAll(".ins-layers button");
    for (var i = 0; i < buttons.length; i++) {
      buttons[i].className = i === state.layer ? "on" : "";
    }
    box.setAttribute("data-layer", layer.name);
    show();
  }

  function setZoom(factor) {
    state.zoom = Math.max(ZOOMS[0], Math.min(ZOOMS[ZOOMS.length - 1], factor));
    img.style.width = (state.w * state.zoom) + "px";
    img.style.height = (state.h * state.zoom) + "px";
    box.querySelector(".ins-factor").textContent = state.zoom + "\u00d7";
    box.setAttribute("data-zoom", String(state.zoom));
  }

  function step(direction) {
    var i = ZOOMS.indexOf(state.zoom);
    if (i < 0) { i = 0; }
    setZoom(ZOOMS[Math.max(0, Math.min(ZOOMS.length - 1, i + direction))]);
  }

  function fit() {
    var width = view.clientWidth || 800, height = view.clientHeight || 600, best = ZOOMS[0];
    ZOOMS.forEach(function (z) {
      if (state.w * z <= width - 8 && state.h * z <= height - 8) { best = Math.max(best, z); }
    });
    setZoom(best);
  }

  function open(groupId, layerIndex, opener) {
    var group = data.groups[groupId];
    if (!group) { return false; }
    state.group = groupId;
    state.layers = group.layers;
    state.opener = opener || null;
    state.section = opener && opener.closest ? opener.closest("section") : null;
    state.x = -1; state.y = -1;
    var size = null;
    group.layers.forEach(function (layer) {
      var lin = linear(layer.lin || layer.a);
      if (!size && lin) { size = [lin.w, lin.h]; }
    });
    if (!size && opener) { size = [opener.naturalWidth || 0, opener.naturalHeight || 0]; }
    state.w = size && size[0] ? size[0] : 64;
    state.h = size && size[1] ? size[1] : 64;
    box.querySelector(".ins-title").textContent = group.title;
    var bar = box.querySelector(".ins-layers");
    bar.textContent = "";
    group.layers.forEach(function (layer, i) {
      var button = document.createElement("button");
      button.type = "button";
      button.textContent = (i + 1) + " " + layer.name;
      button.addEventListener("click", function () { setLayer(i); });
      bar.appendChild(button);
    });
    box.hidden = false;
    fit();
    setLayer(layerIndex || 0);
    box.focus();
    return true;
  }

  function close() {
    box.hidden = true;
    state.group = null;
    if (state.opener && state.opener.focus) { state.opener.focus(); }
  }

  function pointAt(clientX, clientY) {
    var rect = img.getBoundingClientRect();
    if (!rect.width || !rect.height) { return; }
    state.x = Math.floor((clientX - rect.left) * state.w / rect.width);
    state.y = Math.floor((clientY - rect.top) * state.h / rect.height);
    show();
  }

  function key(name) {
    if (box.hidden) { return false; }
    if (name === "Escape") { close(); }
    else if (name === "ArrowRight" || name === " " || name === "Spacebar" || name === "n") {
      setLayer(state.layer + 1);
    } else if (name === "ArrowLeft" || name === "p") { setLayer(state.layer - 1); }
    else if (name === "+" || name === "=") { step(1); }
    else if (name === "-" || name === "_") { step(-1); }
    else if (name === "0") { fit(); }
    else if (/^[1-9]$/.test(name) && Number(name) <= state.layers.length) {
      setLayer(Number(name) - 1);
    } else { return false; }
    return true;
  }

  document.addEventListener("click", function (event) {
    var target = event.target;
    if (!target || !target.getAttribute || !target.hasAttribute("data-ig")) { return; }
    if (event.button !== 0 || event.ctrlKey || event.metaKey || event.shiftKey) { return; }
    if (open(target.getAttribute("data-ig"), Number(target.getAttribute("data-il")), target)) {
      event.preventDefault();
    }
  });
  document.addEventListener("keydown", function (event) {
    if (key(event.key)) { event.preventDefault(); }
  });
  img.addEventListener("mousemove", function (event) { pointAt(event.clientX, event.clientY); });
  img.addEventListener("mouseleave", function () { state.x = -1; state.y = -1; show(); });
  box.querySelector(".ins-close").addEventListener("click", close);
  box.querySelector("[data-zoom=in]").addEventListener("click", function () { step(1); });
  box.querySelector("[data-zoom=out]").addEventListener("click", function () { step(-1); });
  box.querySelector("[data-zoom=fit]").addEventListener("click", fit);

  // "#inspect=<run key>[:<layer number>]" opens the inspector on that run's card.
  var link = /^#inspect=([A-Za-z0-9_.-]+)(?::(\d+))?$/.exec(window.location.hash);
  if (link) {
    var target = document.querySelector('.card[data-key="' + link[1] + '"] img[data-ig]');
    if (target) {
      open(target.getAttribute("data-ig"), link[2] ? Number(link[2]) - 1 : 0, target);
    }
    return;
  }

  // The self-test, "#inspector-selftest[:x,y[:KEY]][;x,y[:KEY]]...": for each item it opens the
  // first image of the first run card (or of the card of run KEY), flips and zooms with key
  // events, points at pixel (x, y) with a mouse event and records what the inspector shows;
  // the records go, as a JSON list, into #inspector-selftest-result.
  var test = /^#inspector-selftest((?:[:;][A-Za-z0-9_.,-]*)*)$/.exec(window.location.hash);
  if (!test) { return; }
  var result = document.getElementById("inspector-selftest-result");
  var specs = test[1].replace(/^:/, "").split(";");

  function selftest(spec) {
    var parts = /^(?:(\d+),(\d+))?(?::([A-Za-z0-9_.-]+))?$/.exec(spec) || [];
    var record = { steps: [] };
    function press(name) {
      document.dispatchEvent(new KeyboardEvent("keydown", { key: name, bubbles: true }));
      record.steps.push({ key: name, layer: box.getAttribute("data-layer"),
                          zoom: Number(box.getAttribute("data-zoom")), open: !box.hidden });
    }
    function read() {
      var out = box.querySelector(".ins-value");
      return { layer: box.getAttribute("data-layer"), text: out.textContent,
               values: out.getAttribute("data-v"),
               pos: box.querySelector(".ins-pos").textContent,
               more: box.querySelector(".ins-more").textContent };
    }
    var first = document.querySelector(parts[3]
      ? '.card[data-key="' + parts[3] + '"] img[data-ig]' : ".card[data-key] img[data-ig]");
    if (!first) {
      record.error = "no inspectable image in a run card";
      return record;
    }
    var x = parts[1] ? Number(parts[1]) : 0, y = parts[2] ? Number(parts[2]) : 0;
    record.key = first.closest(".card").getAttribute("data-key");
    first.dispatchEvent(new MouseEvent("click", { bubbles: true, cancelable: true, button: 0 }));
    record.opened = { layer: box.getAttribute("data-layer"), open: !box.hidden,
                      layers: state.layers.map(function (l) { return l.name; }),
                      size: [state.w, state.h] };
    press("ArrowRight");
    press("3");
    press(" ");
    press("ArrowLeft");
    press("2");
    for (var i = 0; i < 12; i++) { press("-"); }
    press("+");
    press("+");
    record.zoom = state.zoom;
    var rect = img.getBoundingClientRect();
    record.imageWidth = rect.width;
    img.dispatchEvent(new MouseEvent("mousemove", {
      clientX: rect.left + (x + 0.5) * rect.width / state.w,
      clientY: rect.top + (y + 0.5) * rect.height / state.h, bubbles: true }));
    record.pixel = [x, y];
    record.reference = read();
    press("1");
    record.run = read();
    press("3");
    record.error_map = read();
    press("Escape");
    record.closed = box.hidden;
    return record;
  }

  result.textContent = JSON.stringify(specs.map(selftest));
})();
"""
