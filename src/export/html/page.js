// brdfprof report: sortable tables and hover text; no network, no libraries.
"use strict";
(function () {
  function key(cell) {
    if (!cell) return null;
    var v = cell.getAttribute("data-v");
    if (v !== null) {
      var x = parseFloat(v);
      if (isNaN(x)) x = /^-/.test(v) ? -Infinity : Infinity;
      return x;
    }
    return cell.textContent;
  }
  function sortBy(table, th) {
    var col = th.getAttribute("data-col");
    var asc = !th.classList.contains("asc");
    table.querySelectorAll("th").forEach(function (h) { h.classList.remove("asc", "desc"); });
    th.classList.add(asc ? "asc" : "desc");
    var body = table.tBodies[0];
    var rows = Array.prototype.slice.call(body.rows);
    rows.sort(function (a, b) {
      var x = key(a.querySelector('td[data-col="' + col + '"]'));
      var y = key(b.querySelector('td[data-col="' + col + '"]'));
      var c = (typeof x === "number" && typeof y === "number") ? x - y : String(x).localeCompare(String(y));
      return asc ? c : -c;
    });
    rows.forEach(function (r) { body.appendChild(r); });
  }
  document.querySelectorAll("table.sortable").forEach(function (table) {
    table.querySelectorAll("th").forEach(function (th) {
      th.addEventListener("click", function () { sortBy(table, th); });
    });
  });
  var tip = document.getElementById("tip");
  document.addEventListener("mouseover", function (e) {
    var t = e.target.closest ? e.target.closest("[data-tip]") : null;
    if (t) { tip.textContent = t.getAttribute("data-tip"); tip.style.display = "block"; }
    else { tip.style.display = "none"; }
  });
  // Where each section lies on the page (CSS px from the top): what a reader sees on the first screen.
  document.querySelectorAll("main > section").forEach(function (sec) {
    var r = sec.getBoundingClientRect();
    sec.setAttribute("data-top", String(Math.round(r.top + window.scrollY)));
    sec.setAttribute("data-bottom", String(Math.round(r.bottom + window.scrollY)));
  });
  document.body.setAttribute("data-ready", "1");
})();
