
(function () {
  "use strict";
  var box = document.getElementById("inspector");
  var dataNode = document.getElementById("gilab-inspector");
  if (!box || !dataNode) { return; }
  var data = JSON.parse(dataNode.textContent);
  var img = box.querySelector(".ins-img"), view = box.querySelector(".ins-view");
  // panX/panY: the image's top-left corner in the view (CSS px); client: the cursor's last
  // position over the image, pointer: over the view (client coordinates, null when outside).
  var state = { group: null, layers: [], layer: 0, zoom: 1, w: 0, h: 0, x: -1, y: -1,
                section: null, opener: null, panX: 0, panY: 0, client: null, pointer: null,
                drag: null, wheel: 0, wheelAt: 0 };
  var decoded = {}, decodedMaps = {};
  var ZOOMS = [1, 2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64];
  var KEEP = 32;  // px of the image that panning keeps inside the view
  var WHEEL_STEP = 50;  // px of wheel travel (a mouse's notch is 100 or 120) per zoom step

  // The colour bar of error maps (legend from the page's data: metric, range, colour stops).
  var legend = document.createElement("div");
  legend.className = "ins-legend";
  legend.hidden = true;
  legend.innerHTML = '<span class="ins-legend-name"></span><span class="ins-legend-min"></span>' +
    '<span class="ins-legend-bar"><i class="ins-legend-mark" hidden></i></span>' +
    '<span class="ins-legend-max"></span>';
  var file = box.querySelector(".ins-file");
  file.parentNode.insertBefore(legend, file.nextSibling);

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

  // An error map's values read back from its PNG: one byte k per pixel (value k / 255).
  function mapValues(id) {
    if (!id || !data.maps || !data.maps[id]) { return null; }
    if (decodedMaps[id]) { return decodedMaps[id]; }
    var entry = data.maps[id], bin = atob(entry.b64), codes = new Uint8Array(bin.length);
    for (var i = 0; i < bin.length; i++) { codes[i] = bin.charCodeAt(i); }
    var bad = {};
    (entry.bad || []).forEach(function (p) { bad[p] = true; });
    decodedMaps[id] = { w: entry.w, h: entry.h, k: codes, bad: bad, dev: entry.dev || 0 };
    return decodedMaps[id];
  }

  // The map's value at the inspector's pixel (x, y) (scaled when the map's size differs):
  // null outside, NaN where the map has no value.
  function mapAt(id, x, y) {
    var map = mapValues(id);
    if (!map || x < 0 || y < 0 || x >= state.w || y >= state.h) { return null; }
    var mx = map.w === state.w ? x : Math.floor(x * map.w / state.w);
    var my = map.h === state.h ? y : Math.floor(y * map.h / state.h);
    var p = my * map.w + mx;
    return map.bad[p] ? NaN : map.k[p] / 255;
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
      return ["|ΔY| / mean Y = " + fmt(e), [e]];
    }
    if (layer.kind === "map") {
      if (!layer.q) {
        return ["colour only" + (layer.why ? " (no values: " + layer.why + ")" : ""), null];
      }
      var v = mapAt(layer.q, x, y), map = mapValues(layer.q);
      if (v === null) { return ["no value", null]; }
      if (isNaN(v)) { return ["no value (not a colour of the map: NaN is magenta)", null]; }
      var metric = layer.legend ? layer.legend.metric : "value";
      return [metric + " = " + fmt(v) + (map.dev
        ? " (≈: the PNG's colours are up to " + map.dev + "/255 off the runner's magma)"
        : " (±0.002: read back from the PNG's 8-bit colour)"), [v]];
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

  // The legend's marker at value v (hidden when v is not a number).
  function mark(v) {
    var layer = state.layers[state.layer], marker = legend.querySelector(".ins-legend-mark");
    if (!layer || !layer.legend || typeof v !== "number" || !isFinite(v)) {
      marker.hidden = true;
      return;
    }
    var f = (v - layer.legend.min) / (layer.legend.max - layer.legend.min);
    marker.style.left = (100 * Math.max(0, Math.min(1, f))).toFixed(2) + "%";
    marker.hidden = false;
  }

  function show() {
    var x = state.x, y = state.y, layer = state.layers[state.layer];
    var pos = box.querySelector(".ins-pos"), out = box.querySelector(".ins-value");
    var more = box.querySelector(".ins-more");
    if (x < 0 || y < 0 || x >= state.w || y >= state.h) {
      pos.textContent = "move the cursor over the image";
      out.textContent = ""; more.textContent = ""; out.removeAttribute("data-v");
      mark(null);
      return;
    }
    var value = valueOf(layer, x, y);
    pos.textContent = "pixel (" + x + ", " + y + ")";
    out.textContent = layer.name + ": " + value[0];
    out.setAttribute("data-v", value[1] ? value[1].join(" ") : "");
    mark(layer.legend && value[1] ? value[1][0] : null);
    var others = [];
    state.layers.forEach(function (other, i) {
      if (i === state.layer) { return; }
      if (other.kind === "image" && other.lin) {
        var rgb = rgbAt(other.lin, x, y);
        if (rgb) { others.push(other.name + ": " + fmtRgb(rgb)); }
      } else if (other.kind === "relerr" || (other.kind === "map" && other.q)) {
        var e = valueOf(other, x, y)[1];
        if (e) { others.push(other.name + ": " + fmt(e[0])); }
      }
    });
    more.textContent = others.join(" · ");
  }

  function showLegend(layer) {
    var spec = layer.legend;
    legend.hidden = !spec;
    box.setAttribute("data-legend", spec ? spec.metric : "");
    if (!spec) { return; }
    legend.querySelector(".ins-legend-name").textContent = spec.metric;
    legend.querySelector(".ins-legend-min").textContent = spec.minLabel;
    legend.querySelector(".ins-legend-max").textContent = spec.maxLabel;
    legend.title = spec.metric + " from " + spec.minLabel + " to " + spec.maxLabel +
      (spec.note ? ": " + spec.note : "");
    var stops = (data.cmaps && data.cmaps[spec.cmap]) || [];
    legend.querySelector(".ins-legend-bar").style.background = stops.length
      ? "linear-gradient(to right, " + stops.map(function (s) {
        return s[1] + " " + (100 * s[0]).toFixed(2) + "%";
      }).join(", ") + ")" : "";
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
    showLegend(layer);
    show();
  }

  // The image at (panX, panY) in the view, drawn zoom CSS px per pixel.
  function place() {
    img.style.left = state.panX + "px";
    img.style.top = state.panY + "px";
  }

  // Keeps at least KEEP px (or all) of the image inside the view.
  function clampPan() {
    var vw = view.clientWidth, vh = view.clientHeight;
    var iw = state.w * state.zoom, ih = state.h * state.zoom;
    var kx = Math.min(KEEP, iw), ky = Math.min(KEEP, ih);
    state.panX = Math.max(kx - iw, Math.min(vw - kx, state.panX));
    state.panY = Math.max(ky - ih, Math.min(vh - ky, state.panY));
  }

  // Zoom to `factor` keeping the image point under (clientX, clientY) where it is on screen
  // (the view's centre when no point is given; then the image is also kept in view).
  function setZoom(factor, clientX, clientY) {
    var z = Math.max(ZOOMS[0], Math.min(ZOOMS[ZOOMS.length - 1], factor));
    var rect = view.getBoundingClientRect(), anchored = typeof clientX === "number";
    var ax = anchored ? clientX - rect.left - view.clientLeft : view.clientWidth / 2;
    var ay = anchored ? clientY - rect.top - view.clientTop : view.clientHeight / 2;
    var u = (ax - state.panX) / state.zoom, v = (ay - state.panY) / state.zoom;
    state.panX = Math.round(ax - u * z);
    state.panY = Math.round(ay - v * z);
    state.zoom = z;
    if (!anchored) { clampPan(); }
    img.style.width = (state.w * z) + "px";
    img.style.height = (state.h * z) + "px";
    place();
    box.querySelector(".ins-factor").textContent = z + "×";
    box.setAttribute("data-zoom", String(z));
    if (state.client) { pointAt(state.client[0], state.client[1]); }
  }

  function step(direction, clientX, clientY) {
    var i = ZOOMS.indexOf(state.zoom);
    if (i < 0) { i = 0; }
    setZoom(ZOOMS[Math.max(0, Math.min(ZOOMS.length - 1, i + direction))], clientX, clientY);
  }

  // A zoom step about the cursor when it is over the view, else about the view's centre.
  function stepAtPointer(direction) {
    if (state.pointer) { step(direction, state.pointer[0], state.pointer[1]); }
    else { step(direction); }
  }

  function fit() {
    var width = view.clientWidth || 800, height = view.clientHeight || 600, best = ZOOMS[0];
    ZOOMS.forEach(function (z) {
      if (state.w * z <= width - 8 && state.h * z <= height - 8) { best = Math.max(best, z); }
    });
    state.zoom = best;
    state.panX = Math.round((width - state.w * best) / 2);
    state.panY = Math.round((height - state.h * best) / 2);
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
    state.client = null; state.pointer = null; state.drag = null;
    var size = null;
    group.layers.forEach(function (layer) {
      var lin = linear(layer.lin || layer.a) || mapValues(layer.q);
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
    state.client = [clientX, clientY];
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
    else if (name === "+" || name === "=") { stepAtPointer(1); }
    else if (name === "-" || name === "_") { stepAtPointer(-1); }
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
  img.addEventListener("mouseleave", function () {
    state.x = -1; state.y = -1; state.client = null; show();
  });
  view.addEventListener("mousemove", function (event) {
    state.pointer = [event.clientX, event.clientY];
  });
  view.addEventListener("mouseleave", function () { state.pointer = null; });
  // The wheel zooms about the cursor: one step per WHEEL_STEP px of travel (a notch).
  view.addEventListener("wheel", function (event) {
    if (box.hidden) { return; }
    event.preventDefault();
    var unit = event.deltaMode === 1 ? 40 : event.deltaMode === 2 ? 800 : 1;
    var now = Date.now();
    if (now - state.wheelAt > 400) { state.wheel = 0; }
    state.wheelAt = now;
    state.wheel += event.deltaY * unit;
    state.pointer = [event.clientX, event.clientY];
    if (Math.abs(state.wheel) >= WHEEL_STEP) {
      step(state.wheel < 0 ? 1 : -1, event.clientX, event.clientY);
      state.wheel = 0;
    }
  }, { passive: false });
  // Dragging pans.
  view.addEventListener("mousedown", function (event) {
    if (event.button !== 0) { return; }
    event.preventDefault();
    state.drag = [event.clientX, event.clientY, state.panX, state.panY];
    view.classList.add("dragging");
  });
  document.addEventListener("mousemove", function (event) {
    if (!state.drag) { return; }
    state.panX = state.drag[2] + event.clientX - state.drag[0];
    state.panY = state.drag[3] + event.clientY - state.drag[1];
    clampPan();
    place();
  });
  document.addEventListener("mouseup", function () {
    state.drag = null;
    view.classList.remove("dragging");
  });
  window.addEventListener("resize", function () {
    if (!box.hidden) { clampPan(); place(); }
  });
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
