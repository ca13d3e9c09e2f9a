#include "monitor/page.h"

#include "core/html_escape.h"

namespace rths::monitor {
namespace {

// The page's script keeps every point it was sent (up to kKeep), draws the chosen window, and
// exposes its state as window.rths for tests (points, lastT, status, abortMessage).
constexpr const char* kHead = R"HTML(<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>@TITLE@</title>
<script src="dygraph.min.js"></script>
<style>
body { font: 14px/1.4 system-ui, sans-serif; margin: 0; background: #f6f7f9; color: #1c2330; }
header { display: flex; align-items: center; gap: 16px; padding: 10px 18px; background: #1c2330; color: #fff; }
header h1 { font-size: 18px; margin: 0; font-weight: 600; }
#badge { padding: 3px 10px; border-radius: 12px; font-weight: 600; background: #6b7280; }
#badge.running, #badge.finishing { background: #2563eb; } #badge.starting { background: #b45309; }
#badge.completed { background: #15803d; } #badge.aborted { background: #b91c1c; }
#abort { margin-left: auto; font: 700 16px system-ui, sans-serif; color: #fff; background: #dc2626;
         border: 2px solid #7f1d1d; border-radius: 6px; padding: 8px 22px; cursor: pointer; }
#abort:disabled { background: #9ca3af; border-color: #6b7280; cursor: default; }
#stats { padding: 8px 18px; display: flex; flex-wrap: wrap; gap: 6px 22px; background: #fff; border-bottom: 1px solid #d9dde3; }
#stats b { font-variant-numeric: tabular-nums; }
#limits { padding: 6px 18px; display: flex; flex-wrap: wrap; gap: 6px 22px; background: #fff; border-bottom: 1px solid #d9dde3; }
#limits b { font-variant-numeric: tabular-nums; } #limits b.near { color: #b45309; } #limits b.over { color: #b91c1c; }
#stats i { color: #6b7280; font-style: normal; font-size: 12px; }
#message { padding: 6px 18px; min-height: 20px; color: #b91c1c; font-weight: 600; }
#controls { padding: 0 18px 6px; } #controls button { margin-right: 4px; }
#controls button.on { background: #1c2330; color: #fff; }
.grid { display: grid; grid-template-columns: 1fr 1fr; gap: 10px; padding: 0 18px 18px; }
.panel { background: #fff; border: 1px solid #d9dde3; border-radius: 6px; padding: 6px 8px 2px; }
.panel.wide { grid-column: 1 / 3; }
.panel h2 { font-size: 13px; margin: 0 0 2px; font-weight: 600; display: flex; justify-content: space-between; }
.panel h2 span { font-weight: 400; color: #4b5563; }
.plot { width: 100%; height: 210px; } .plot.tall { height: 250px; }
.hidden { display: none; }
.dygraph-xlabel { font-size: 12px; } .dygraph-axis-label { font-size: 11px; }
</style></head>
<body>
<header><h1>@TITLE@</h1><span id="badge">waiting</span><span id="runid"></span>
<button id="abort" disabled title="Send ABORT to every participant: the run stops, its log complete to its last step">ABORT</button></header>
<div id="stats"><span>step <b id="step">-</b></span><span>t <b id="time">-</b></span>
<span>rate <b id="rate">-</b></span><span id="pacedstats" class="hidden">latency <b id="latency">-</b>,
misses <b id="misses">-</b> <i>(the clock's, as summary.json counts them)</i></span><span>monitor heard <b id="heard">-</b></span></div>
<div id="limits"><span>safety limits, the run's peak so far:</span>
<span>stroke (max |r|, |u|, |y|) <b id="lim_disp">-</b></span><span>force <b id="lim_force">-</b></span><span>|r &minus; y| <b id="lim_err">-</b></span></div>
<div id="message"></div>
<div id="controls">window <button data-s="2">2 s</button><button data-s="10" class="on">10 s</button><button data-s="0">all</button></div>
<div class="grid">
<div class="panel wide"><h2>Displacement [mm]<span id="disp_legend"></span></h2><div id="disp" class="plot tall"></div></div>
<div class="panel wide"><h2>Tracking error r &minus; y [mm]<span id="err_legend"></span></h2><div id="err" class="plot tall"></div></div>
<div class="panel"><h2>Specimen force [kN]<span id="force_legend"></span></h2><div id="force" class="plot"></div></div>
<div class="panel"><h2>Damper current [A]<span id="cur_legend"></span></h2><div id="cur" class="plot"></div></div>
<div class="panel wide hidden" id="latpanel"><h2>Step latency, the clock's: release to barrier, largest per point [ms] (red line: the deadline, dt)<span id="lat_legend"></span></h2><div id="lat" class="plot"></div></div>
</div>
)HTML";

constexpr const char* kScript = R"HTML(<script>
"use strict";
const token = new URLSearchParams(location.search).get("token") || "";
const kKeep = 200000;
const st = { runId: null, rows: [], status: null, points: 0, lastT: -1, abortMessage: "", windowS: 10, updates: 0 };
window.rths = st;
const $ = (id) => document.getElementById(id);
const tick = (v) => String(Number(Number(v).toPrecision(3)));
const common = { xlabel: "t [s]", xLabelHeight: 16, legend: "always", strokeWidth: 1.3, connectSeparatedPoints: false,
                 drawGrid: true, gridLineColor: "#e5e7eb", animatedZooms: false,
                 axes: { y: { axisLabelFormatter: tick, axisLabelWidth: 56 } } };
function plot(id, labels, colors, extra) {
  const empty = [[0].concat(labels.slice(1).map(() => null))];
  return new Dygraph($(id), empty, Object.assign({ labels, colors, labelsDiv: id + "_legend" }, common, extra || {}));
}
const plots = {
  disp: plot("disp", ["t", "r (desired)", "u (command)", "y (measured)"], ["#111827", "#f59e0b", "#2563eb"],
             { series: { "r (desired)": { strokePattern: [6, 3], strokeWidth: 2 } } }),
  err: plot("err", ["t", "r - y"], ["#dc2626"]),
  force: plot("force", ["t", "f"], ["#7c3aed"]),
  cur: plot("cur", ["t", "i"], ["#059669"]),
  lat: plot("lat", ["t", "latency"], ["#0f766e"]),
};
const columns = { disp: [1, 2, 3], err: [4], force: [5], cur: [6], lat: [7] };
function fmt(x, d) { return x === null || x === undefined || !isFinite(x) ? "-" : Number(x).toFixed(d); }
function redraw() {
  const rows = st.rows;
  if (!rows.length) return;
  const t1 = rows[rows.length - 1][0];
  const win = st.windowS > 0 ? [Math.max(0, t1 - st.windowS), Math.max(t1, st.windowS)] : null;
  let from = 0;
  if (win) { while (from < rows.length - 1 && rows[from][0] < win[0]) from++; }
  for (const [name, cols] of Object.entries(columns)) {
    if (name === "lat" && !(st.status && st.status.paced)) continue;
    const data = [];
    for (let n = from; n < rows.length; n++) data.push([rows[n][0]].concat(cols.map((c) => rows[n][c])));
    const opts = { file: data, dateWindow: win };
    if (name === "lat") opts.underlayCallback = (ctx, area, g) => {
      const y = g.toDomYCoord(1000 * st.status.dt_s); ctx.strokeStyle = "#dc2626"; ctx.beginPath();
      ctx.moveTo(area.x, y); ctx.lineTo(area.x + area.w, y); ctx.stroke(); };
    plots[name].updateOptions(opts);
  }
  st.updates++;
}
// The run's peak against its safety limit: "12.3 of 152.4 mm (8 %)", amber from 80 %, red at 100 %.
function limit(id, peak, lim, unit, d) {
  const e = $(id);
  if (!(lim > 0)) { e.textContent = fmt(peak, d) + " " + unit + " (no limit)"; e.className = ""; return; }
  const share = 100 * peak / lim;
  e.textContent = fmt(peak, d) + " of " + fmt(lim, d) + " " + unit + " (" + fmt(share, 0) + " %)";
  e.className = share >= 100 ? "over" : share >= 80 ? "near" : "";
}
function showStatus(s) {
  st.status = s;
  const badge = $("badge");
  badge.textContent = s.phase; badge.className = s.phase;
  $("runid").textContent = s.run_id !== "0" ? "run " + s.run_id : "";
  const n = s.n_steps, k = s.last_k + 1;
  $("step").textContent = n > 0 ? k.toLocaleString("en") + " of " + n.toLocaleString("en") + " (" + fmt(100 * k / n, 0) + " %)" : "-";
  $("time").textContent = s.dt_s > 0 ? fmt(k * s.dt_s, 2) + " s of " + fmt(n * s.dt_s, 1) + " s" : "-";
  $("rate").textContent = s.steps_per_s > 0 ? Math.round(s.steps_per_s).toLocaleString("en") + " steps/s (" +
      fmt(s.steps_per_s * s.dt_s, 2) + "x real time)" : "-";
  $("heard").textContent = s.records_expected > 0 ?
      fmt(100 * s.records_heard / s.records_expected, 1) + " % of the clock's records" : "-";
  limit("lim_disp", s.peaks.disp_mm, s.limits.stroke_mm, "mm", 1);
  limit("lim_force", s.peaks.force_kN, s.limits.force_kN, "kN", 2);
  limit("lim_err", s.peaks.error_mm, s.limits.max_error_mm, "mm", 2);
  $("pacedstats").classList.toggle("hidden", !s.paced);
  $("latpanel").classList.toggle("hidden", !s.paced);
  if (s.paced) {
    $("latency").textContent = fmt(s.latency_ms, 2) + " ms (max " + fmt(s.latency_max_ms, 2) + " ms)";
    $("misses").textContent = s.misses + (s.misses ? " (longest run " + s.longest_miss_run + ")" : "");
  }
  $("abort").disabled = !(s.phase === "starting" || s.phase === "running");
  if (s.phase === "aborted") $("message").textContent = "Aborted by " + s.abort_by + ": " + s.abort_reason;
  else if (s.phase === "completed") $("message").textContent = "";
}
function onEvent(e) {
  const j = JSON.parse(e.data);
  if (j.status.run_id !== st.runId) { st.runId = j.status.run_id; st.rows = []; st.points = 0; }
  for (const p of j.points) st.rows.push(p);
  if (st.rows.length > kKeep) st.rows.splice(0, st.rows.length - kKeep);
  st.points += j.points.length;
  if (st.rows.length) st.lastT = st.rows[st.rows.length - 1][0];
  showStatus(j.status);
  if (j.points.length) scheduleRedraw();
}
// At most 4 redraws a second: a scope that is read by eye, and a browser on the rig's own machine
// takes less of its CPU.
let redrawPending = false, lastRedraw = 0;
function scheduleRedraw() {
  if (redrawPending) return;
  redrawPending = true;
  setTimeout(() => { redrawPending = false; lastRedraw = performance.now(); redraw(); },
             Math.max(0, 250 - (performance.now() - lastRedraw)));
}
if (window.rthsSnapshot) {
  // A snapshot (?snapshot=1): the state at the moment the page was asked for, drawn at once and
  // never updated, so `chromium --headless --screenshot` captures a run that is still going.
  st.snapshot = true;
  onEvent({ data: JSON.stringify(window.rthsSnapshot) });
  redraw();
  $("abort").disabled = true;
} else {
  const source = new EventSource("events?token=" + encodeURIComponent(token));
  source.onmessage = onEvent;
  source.onerror = () => { if (!st.status || (st.status.phase !== "completed" && st.status.phase !== "aborted"))
    $("message").textContent = "lost the monitor (reconnecting)"; };
  source.onopen = () => { if ($("message").textContent.startsWith("lost")) $("message").textContent = ""; };
}
$("abort").addEventListener("click", () => {
  $("abort").disabled = true;
  fetch("abort?token=" + encodeURIComponent(token), { method: "POST" })
    .then((r) => r.json()).then((j) => {
      st.abortMessage = j.message;
      // The run's own word wins: its "Aborted by ..." may have come over the events first.
      if (!st.status || st.status.phase !== "aborted") $("message").textContent = j.ok ? "ABORT sent" : j.message; })
    .catch((err) => { st.abortMessage = String(err); $("message").textContent = "ABORT could not be sent: " + err; });
});
for (const b of document.querySelectorAll("#controls button")) {
  b.addEventListener("click", () => {
    st.windowS = Number(b.dataset.s);
    for (const o of document.querySelectorAll("#controls button")) o.classList.toggle("on", o === b);
    redraw();
  });
}
</script></body></html>
)HTML";

}  // namespace

std::string PageHtml(const std::string& title, const std::string& snapshot_json) {
  std::string page = kHead;
  const std::string escaped = HtmlEscape(title);
  for (std::size_t at; (at = page.find("@TITLE@")) != std::string::npos;) page.replace(at, 7, escaped);
  if (!snapshot_json.empty()) {
    // Inside a script element "</" would end it early: JSON reads "<\/" as "</".
    std::string json = snapshot_json;
    for (std::size_t at = 0; (at = json.find("</", at)) != std::string::npos; at += 3) json.replace(at, 2, "<\\/");
    page += "<script>window.rthsSnapshot = " + json + ";</script>\n";
  }
  return page + kScript;
}

}  // namespace rths::monitor
