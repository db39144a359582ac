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
  document.body.setAttribute("data-page-height", String(document.documentElement.scrollHeight));
  // Layout facts a reader would notice, recorded for tests: text boxes of one picture that overlap (by more
  // than a pixel each way), and how wide each table is against the page. Folded blocks are opened while they
  // are measured (a closed one lays nothing out) and closed again.
  var folded = Array.prototype.slice.call(document.querySelectorAll("details:not([open])"));
  folded.forEach(function (d) { d.open = true; });
  function overlaps(a, b) {
    return Math.min(a.right, b.right) - Math.max(a.left, b.left) > 1 &&
      Math.min(a.bottom, b.bottom) - Math.max(a.top, b.top) > 1;
  }
  document.querySelectorAll("svg").forEach(function (svg) {
    var boxes = [];
    svg.querySelectorAll("text").forEach(function (t) {
      var r = t.getBoundingClientRect();
      if (r.width > 0 && r.height > 0) boxes.push([t.textContent, r]);
    });
    var pairs = [];
    for (var i = 0; i < boxes.length; i++)
      for (var j = i + 1; j < boxes.length; j++)
        if (overlaps(boxes[i][1], boxes[j][1])) pairs.push(boxes[i][0] + " / " + boxes[j][0]);
    svg.setAttribute("data-texts", String(boxes.length));
    svg.setAttribute("data-overlaps", String(pairs.length));
    if (pairs.length) svg.setAttribute("data-overlap-pairs", pairs.slice(0, 5).join(" | "));
  });
  // A table wider than its section scrolls inside it: its first column must stay in view (sticky).
  var unsticky = [];
  document.querySelectorAll("table").forEach(function (t) {
    var w = t.getBoundingClientRect().width;
    t.setAttribute("data-width", String(Math.round(w)));
    var sec = t.closest("section");
    var first = t.querySelector("tr > :first-child");
    if (sec && w > sec.clientWidth && !(first && getComputedStyle(first).position === "sticky"))
      unsticky.push(t.querySelector("tr") ? t.querySelector("tr").textContent.slice(0, 40) : "?");
  });
  document.body.setAttribute("data-wide-unsticky", String(unsticky.length));
  if (unsticky.length) document.body.setAttribute("data-wide-unsticky-tables", unsticky.join(" | "));
  folded.forEach(function (d) { d.open = false; });
  document.body.setAttribute("data-page-width", String(document.documentElement.clientWidth));
  document.body.setAttribute("data-ready", "1");
})();
