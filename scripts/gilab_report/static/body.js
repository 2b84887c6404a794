
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
