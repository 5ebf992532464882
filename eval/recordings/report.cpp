#include "eval/recordings/report.h"

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>

#include "base/format.h"

namespace oal {
namespace {

constexpr const char* kDefaultChartJs = "/usr/share/javascript/chart.js/chart.min.js";

std::string Base64(const std::vector<unsigned char>& bytes) {
  static const char kDigits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const unsigned int b0 = bytes[i];
    const unsigned int b1 = i + 1 < bytes.size() ? bytes[i + 1] : 0u;
    const unsigned int b2 = i + 2 < bytes.size() ? bytes[i + 2] : 0u;
    const unsigned int triple = (b0 << 16) | (b1 << 8) | b2;
    out += kDigits[(triple >> 18) & 63];
    out += kDigits[(triple >> 12) & 63];
    out += i + 1 < bytes.size() ? kDigits[(triple >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? kDigits[triple & 63] : '=';
  }
  return out;
}

// A JSON block the page script reads; "</" is escaped so no string can end the <script>.
std::string JsonBlock(const char* id, const Json& value) {
  std::string text = value.dump(-1, ' ', false, Json::error_handler_t::replace);
  std::string safe;
  safe.reserve(text.size());
  for (std::size_t i = 0; i < text.size(); ++i) {
    safe += text[i];
    if (text[i] == '<' && i + 1 < text.size() && text[i + 1] == '/') safe += "\\";
  }
  return std::string("<script type=\"application/json\" id=\"") + id + "\">" + safe + "</script>\n";
}

const char* kStyle = R"(<style>
body{font-family:system-ui,sans-serif;margin:1.5em;color:#222;max-width:1200px}
h1{font-size:1.4em}h2{font-size:1.15em;margin-top:1.6em;border-bottom:1px solid #ccc}
table{border-collapse:collapse;margin:.5em 0}td,th{border:1px solid #ccc;padding:3px 8px;
text-align:right}th{background:#f3f3f3}td.l,th.l{text-align:left}
.plot{position:relative;height:260px;margin:.8em 0}.bad{color:#b00}
.thumbs{display:flex;flex-wrap:wrap;gap:10px}.thumbs figure{margin:0;max-width:330px}
figcaption{font-size:.85em}code{background:#f3f3f3;padding:0 3px}
</style>
)";

// Shared by both pages: a chart() that creates one Chart and marks its canvas, and the
// palette. `charts` counts the canvases drawn; the page sets body[data-charts] at the end.
const char* kCommonScript = R"(
const palette = ['#1f77b4','#ff7f0e','#2ca02c','#d62728','#9467bd','#8c564b','#e377c2',
                 '#7f7f7f','#bcbd22','#17becf'];
let charts = 0;
function chart(id, config) {
  const canvas = document.getElementById(id);
  if (!canvas) return;
  config.options = Object.assign({animation: false, responsive: true,
      maintainAspectRatio: false, normalized: true, spanGaps: false,
      interaction: {mode: 'nearest', intersect: false}}, config.options || {});
  new Chart(canvas, config);
  canvas.setAttribute('data-drawn', '1');
  charts++;
}
function series(values, label, i, extra) {
  return Object.assign({label: label, data: values, borderColor: palette[i % 10],
      backgroundColor: palette[i % 10], pointRadius: 0, borderWidth: 1.5}, extra || {});
}
function axes(x, y, y2) {
  const scales = {x: {title: {display: true, text: x}}, y: {title: {display: true, text: y}}};
  if (y2) scales.y2 = {position: 'right', title: {display: true, text: y2},
                       grid: {drawOnChartArea: false}};
  return {scales: scales};
}
function fixed(v, d) { return v === null || v === undefined ? '—' : Number(v).toFixed(d); }
)";

// The input page's plots, from #oal-data and #oal-timing.
const char* kInputScript = R"(
const data = JSON.parse(document.getElementById('oal-data').textContent);
const timing = JSON.parse(document.getElementById('oal-timing').textContent);
const s = data.series, frames = s.frame;
chart('chart-status', {type: 'line', data: {labels: frames, datasets: [
    series(s.status, 'status (3 pose, 2 detected, 1 partial, 0 lost, -1 unreadable)', 0,
           {stepped: true}),
    series(s.held, 'lines held', 1, {yAxisID: 'y2', stepped: true})]},
  options: (function() {
    const o = axes('frame', 'status', 'lines held');
    // Half a step of room above 3 (pose) and below -1: the trace is not hidden on the frame.
    Object.assign(o.scales.y, {min: -1.5, max: 3.5,
                               ticks: {stepSize: 0.5, callback: v => Math.abs(v - Math.round(v)) < 1e-6
                                                                 ? Math.round(v) : null}});
    Object.assign(o.scales.y2, {min: 0, ticks: {stepSize: 1}});
    return o;
  })()});
function perKey(obj, prefix, name) {
  return Object.keys(obj).map((k, i) => series(obj[k], prefix + (name ? name(k) : k), i));
}
// A rendered data set's truth lines are the target's lines, numbered 1-4 as everywhere else;
// a CSV's keep the CSV's own line numbers.
const targetTruth = data.summary.truth && data.summary.truth.kind === 'json';
const truthLine = targetTruth ? 'target line ' : 'truth line ';
const truthName = targetTruth ? (k => String(Number(k) + 1)) : null;
chart('chart-rho', {type: 'line', data: {labels: frames, datasets: perKey(s.rho, 'track #')},
  options: axes('frame', 'rho (px)')});
chart('chart-theta', {type: 'line',
  data: {labels: frames, datasets: perKey(s.theta_deg, 'track #')},
  options: axes('frame', 'theta (deg)')});
if (document.getElementById('chart-line-errors')) {
  chart('chart-line-errors', {type: 'line',
    data: {labels: frames, datasets: perKey(s.offset_px, 'offset, ' + truthLine, truthName)
        .concat(perKey(s.angle_deg, 'angle, ' + truthLine, truthName).map(d =>
            Object.assign(d, {yAxisID: 'y2', borderDash: [4, 3]})))},
    options: axes('frame', 'offset (px)', 'angle (deg)')});
}
if (document.getElementById('chart-pose-errors')) {
  chart('chart-pose-errors', {type: 'line', data: {labels: frames, datasets: [
      series(s.pose_t_mm, 'translation error (mm)', 0),
      series(s.pose_r_deg, 'rotation error (deg)', 1, {yAxisID: 'y2'})]},
    options: axes('frame', 'mm', 'deg')});
}
function histogram(values, bins, hmax) {
  const counts = new Array(bins).fill(0);
  for (const v of values) {
    if (v === null || v === undefined) continue;
    counts[Math.min(bins - 1, Math.floor(v / hmax * bins))]++;
  }
  return counts;
}
const ts = timing.series;
const processing = ts.track_us.map((t, i) => t === null ? null : t + (ts.pose_us[i] || 0));
const all = processing.concat(ts.decode_us).filter(v => v !== null).sort((a, b) => a - b);
const hmax = Math.max(1, all.length ? all[Math.floor(0.99 * (all.length - 1))] * 1.05 : 1);
const bins = 40, labels = [];
for (let b = 0; b < bins; ++b) labels.push(Math.round((b + 0.5) * hmax / bins));
chart('chart-timing', {type: 'bar', data: {labels: labels, datasets: [
    series(histogram(processing, bins, hmax), 'track + pose', 0),
    series(histogram(ts.decode_us, bins, hmax), 'decode', 1)]},
  options: Object.assign(axes('time per frame (µs; last bin: slower)', 'frames'),
                         {interaction: {mode: 'index', intersect: false}})});
const t = document.getElementById('timing-table');
const row = (name, st) => '<tr><td class="l">' + name + '</td><td>' + fixed(st.median, 0) +
    '</td><td>' + fixed(st.p95, 0) + '</td><td>' + fixed(st.max, 0) + '</td></tr>';
t.innerHTML = '<tr><th class="l">stage</th><th>median (µs)</th><th>p95 (µs)</th>' +
    '<th>max (µs)</th></tr>' + row('decode', timing.decode_us) + row('track', timing.track_us) +
    row('pose', timing.pose_us);
document.getElementById('timing-text').textContent = 'wall ' + fixed(timing.wall_s, 2) +
    ' s; decoding ' + fixed(timing.decode_total_s, 2) + ' s; the evaluation costs ' +
    fixed(100 * timing.overhead_vs_decode, 1) + ' % more than decoding alone' +
    (timing.video ? ' (annotated video written)' : ' (no annotated video)') + '.';
document.body.setAttribute('data-charts', String(charts));
)";

const char* kIndexScript = R"(
const data = JSON.parse(document.getElementById('oal-data').textContent);
const timing = JSON.parse(document.getElementById('oal-timing').textContent);
timing.forEach((tm, i) => {
  const cell = document.getElementById('wall-' + i);
  if (cell && tm) cell.textContent = fixed(tm.wall_s, 2) + ' s / ' +
      fixed(100 * tm.overhead_vs_decode, 1) + ' %';
});
const done = data.inputs.filter(x => x.summary);
if (done.length) {
  chart('chart-inputs', {type: 'bar', data: {labels: done.map(x => x.name), datasets: [
      series(done.map(x => x.summary.detection.rate), 'detection rate', 0),
      series(done.map(x => x.summary.pose ? x.summary.pose.availability : null),
             'pose availability', 1)]},
    options: (function() {
      const o = axes('input', 'fraction of readable frames');
      Object.assign(o.scales.y, {min: 0, max: 1});
      return o;
    })()});
}
document.body.setAttribute('data-charts', String(charts));
)";

std::string Head(const std::string& title, const std::string& chart_js) {
  return "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>" +
         MarkupEscaped(title) + "</title>\n" + kStyle + "<script>\n" + chart_js + "\n</script>\n" +
         "</head>\n";
}

std::string Canvas(const char* id, const char* title) {
  return std::string("<h3>") + title +
         "</h3><div class=\"plot\"><canvas class=\"oal-chart\" id=\"" + id + "\"></canvas></div>\n";
}

std::string Number(const Json& value, int digits) {
  if (!value.is_number()) return "—";
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(digits);
  out << value.get<double>();
  return out.str();
}

std::string Percent(const Json& value) {
  return value.is_number() ? Number(Json(100.0 * value.get<double>()), 1) + " %" : "—";
}

std::string Row(const std::string& name, const std::string& value) {
  return "<tr><th class=\"l\">" + MarkupEscaped(name) + "</th><td class=\"l\">" + value +
         "</td></tr>\n";
}

// "mean / p95 / max" of a Stats() object.
std::string Spread(const Json& stats, int digits) {
  return Number(stats.value("mean", Json()), digits) + " / " +
         Number(stats.value("p95", Json()), digits) + " / " +
         Number(stats.value("max", Json()), digits);
}

std::string List(const Json& items, const std::string& empty) {
  if (!items.is_array() || items.empty()) return "<p>" + empty + "</p>\n";
  std::string out = "<ul>\n";
  for (const Json& item : items) {
    out += "<li>" + MarkupEscaped(item.is_string() ? item.get<std::string>() : item.dump()) +
           "</li>\n";
  }
  return out + "</ul>\n";
}

std::string CompareTable(const Json& compare) {
  if (compare.is_null()) return "";
  std::string out = "<h2>Comparison with other methods</h2>\n";
  if (compare.contains("error")) {
    return out + "<p class=\"bad\">" + MarkupEscaped(compare["error"].get<std::string>()) +
           "</p>\n";
  }
  out += "<p>Truth: " + MarkupEscaped(compare.value("truth", "")) +
         " (the line detectors compared; NAME/compare/compare.md)</p>\n<table><tr><th "
         "class=\"l\">method</th>"
         "<th>frames all found</th><th>angle err mean (°)</th><th>offset err mean (px)</th>"
         "<th>time / frame median (µs)</th></tr>\n";
  for (const Json& m : compare.value("methods", Json::array())) {
    const Json angle = m.contains("angle_error_deg") ? m["angle_error_deg"]["mean"] : Json();
    const Json offset = m.contains("offset_error_px") ? m["offset_error_px"]["mean"] : Json();
    const std::string found = m.contains("frames_all_found")
                                  ? std::to_string(m["frames_all_found"].get<int>()) + " / " +
                                        std::to_string(m["frames"].get<int>())
                                  : "—";
    out += "<tr><td class=\"l\">" + MarkupEscaped(m.value("name", "")) + "</td><td>" + found +
           "</td><td>" + Number(angle, 3) + "</td><td>" + Number(offset, 2) + "</td><td>" +
           Number(m.value("time_us_per_frame_median", Json()), 0) + "</td></tr>\n";
  }
  return out + "</table>\n";
}

// "0", or "2: frames 2089, 2119" (the frames the summary lists).
std::string Jumps(const Json& pose) {
  const int count = pose.value("jumps", 0);
  std::string text = std::to_string(count);
  if (count == 0 || !pose.contains("jump_frames")) return text;
  text += ": frame" + std::string(count > 1 ? "s " : " ");
  const Json& frames = pose["jump_frames"];
  for (std::size_t i = 0; i < frames.size(); ++i) {
    text += (i > 0 ? ", " : "") + frames[i].dump();
  }
  if (static_cast<std::size_t>(count) > frames.size()) text += ", ...";
  return "<span class=\"bad\">" + text + "</span>";
}

}  // namespace

std::string ChartJsPath() {
  const char* path = std::getenv("OAL_CHARTJS");
  return path != nullptr && *path != '\0' ? path : kDefaultChartJs;
}

std::string LoadChartJs() {
  const std::string path = ChartJsPath();
  std::ifstream in(path, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in.good() && !in.eof()) text.clear();
  if (text.empty()) {
    throw std::runtime_error("the report needs Chart.js, not found at '" + path +
                             "': install Debian's libjs-chart.js (scripts/install-deps.sh) or "
                             "set OAL_CHARTJS to a chart.min.js (version 3 or 4)");
  }
  return text;
}

std::string InputReportHtml(const Json& summary, const Json& series, const Json& timing,
                            const std::vector<Thumbnail>& thumbnails, const std::string& chart_js) {
  const std::string name = summary.value("name", "input");
  std::string html = Head("Evaluation of " + name, chart_js);
  html += "<body>\n<h1>Evaluation of " + MarkupEscaped(name) + "</h1>\n";
  html += "<p><a href=\"../index.html\">index</a> · input <code>" +
          MarkupEscaped(summary.value("input", "")) + "</code></p>\n";

  const Json& detection = summary["detection"];
  const Json& pose = summary["pose"];
  const Json& truth = summary["truth"];
  html += "<h2>Summary</h2>\n<table>\n";
  html +=
      Row("frames (read / unreadable)",
          std::to_string(summary.value("frames_readable", 0)) + " / " +
              std::to_string(summary.value("frames_unreadable", 0)) +
              (summary["frames_expected"].is_number()
                   ? " (" + std::to_string(summary["frames_expected"].get<int>()) + " announced)"
                   : ""));
  html += Row("image size", std::to_string(summary.value("width", 0)) + " × " +
                                std::to_string(summary.value("height", 0)));
  html += Row(
      "detection rate (≥ " + std::to_string(detection.value("target_lines", 0)) + " lines held)",
      Percent(detection["rate"]));
  html += Row("lost-track episodes (longest, frames)",
              std::to_string(detection.value("lost_episodes", 0)) + " (" +
                  std::to_string(detection.value("longest_lost_frames", 0)) + ")");
  html += Row("tracks started / track losses",
              std::to_string(detection.value("tracks_started", 0)) + " / " +
                  std::to_string(detection.value("track_losses", 0)));
  html += Row("pose availability",
              pose.is_null() ? "no camera: no pose" : Percent(pose["availability"]));
  if (!pose.is_null()) html += Row("pose jumps (lines relabelled, or turned > 90°)", Jumps(pose));
  html +=
      Row("camera", summary["camera"].is_string()
                        ? "<code>" + MarkupEscaped(summary["camera"].get<std::string>()) + "</code>"
                        : "none");
  if (truth.is_null()) {
    html += Row("truth", "none");
  } else {
    html += Row("truth", MarkupEscaped(truth.value("kind", "")) + " <code>" +
                             MarkupEscaped(truth.value("path", "")) + "</code>");
    html += Row("truth lines found", std::to_string(truth.value("found_lines", 0)) + " / " +
                                         std::to_string(truth.value("truth_lines", 0)));
    html += Row("line angle error mean / p95 / max (°)", Spread(truth["angle_deg"], 3));
    html += Row("line offset error mean / p95 / max (px)", Spread(truth["offset_px"], 2));
    html += Row("pose translation error mean / p95 / max (mm)",
                Spread(truth["pose_translation_mm"], 1));
    html += Row("pose rotation error mean / p95 / max (°)", Spread(truth["pose_rotation_deg"], 2));
  }
  html += "</table>\n";
  html += "<h2>Warnings</h2>\n" + List(summary["warnings"], "None.");
  html += "<h2>Unreadable frames</h2>\n";
  if (summary.value("frames_unreadable", 0) == 0) {
    html += "<p>None.</p>\n";
  } else {
    html += "<p class=\"bad\">" + std::to_string(summary.value("frames_unreadable", 0)) +
            " frame(s) skipped (at most 100 listed; frames a truncated video announces but "
            "does not hold are counted, see the warnings).</p>\n<ul>\n";
    for (const Json& item : summary["unreadable"]) {
      html += "<li>frame " + std::to_string(item.value("frame", 0)) + ": " +
              MarkupEscaped(item.value("error", "")) + "</li>\n";
    }
    html += "</ul>\n";
  }

  html += "<h2>Plots</h2>\n";
  html += Canvas("chart-status", "Detection and pose status over time");
  html += Canvas("chart-rho", "Line parameters over time: rho (tracks seen longest)");
  html += Canvas("chart-theta", "Line parameters over time: theta");
  if (!truth.is_null()) {
    html += Canvas("chart-line-errors", "Line errors against the truth");
    if (truth.value("pose_frames", 0) > 0) {
      html += Canvas("chart-pose-errors", "Pose errors against the truth");
    }
  }
  html += Canvas("chart-timing", "Time per frame (histogram)");
  html += "<p id=\"timing-text\"></p>\n<table id=\"timing-table\"></table>\n";

  html += "<h2>Worst frames</h2>\n";
  if (thumbnails.empty()) {
    html += "<p>None (no frame lost a line, missed its pose or erred against the truth).</p>\n";
  } else {
    html +=
        "<p>Frames with a problem, worst first: as many as the evaluation was asked to show, at "
        "least " +
        std::to_string(kThumbnailSpacingFrames) +
        " frames apart (fewer when fewer frames had one).</p>\n";
    html += "<div class=\"thumbs\">\n";
    for (const Thumbnail& thumbnail : thumbnails) {
      html += "<figure><img alt=\"frame " + std::to_string(thumbnail.frame) +
              "\" src=\"data:image/jpeg;base64," + Base64(thumbnail.jpeg) +
              "\"><figcaption>frame " + std::to_string(thumbnail.frame) + ": " +
              MarkupEscaped(thumbnail.why) + "</figcaption></figure>\n";
    }
    html += "</div>\n";
  }
  html += CompareTable(summary["compare"]);

  html += JsonBlock("oal-data", Json{{"summary", summary}, {"series", series}});
  html += JsonBlock("oal-timing", timing);
  html += std::string("<script>\n(function() {\n'use strict';") + kCommonScript + kInputScript +
          "})();\n</script>\n";
  html += "</body>\n</html>\n";
  return html;
}

std::string IndexHtml(const Json& run, const std::vector<Json>& timing,
                      const std::string& chart_js) {
  std::string html = Head("Evaluation", chart_js);
  html += "<body>\n<h1>Evaluation</h1>\n";
  if (run["shard"].is_string()) {
    html += "<p>Shard " + MarkupEscaped(run["shard"].get<std::string>()) + " of the inputs.</p>\n";
  }
  html +=
      "<h2>Inputs</h2>\n<table>\n<tr><th class=\"l\">input</th><th>frames</th>"
      "<th>unreadable</th><th>detection rate</th><th>lost episodes</th>"
      "<th>pose availability</th><th>line offset mean (px)</th>"
      "<th>pose error mean (mm)</th><th title=\"the input's wall-clock time, and how much longer "
      "it took than decoding its frames alone\">time (s) / over decoding alone</th></tr>\n";
  std::string failed;
  std::size_t i = 0;
  for (const Json& input : run["inputs"]) {
    const std::string name = input.value("name", "");
    const Json& summary = input["summary"];
    if (summary.is_null()) {
      failed += "<li><code>" + MarkupEscaped(input.value("input", "")) +
                "</code>: " + MarkupEscaped(input.value("error", "")) + "</li>\n";
      html += "<tr><td class=\"l bad\">" + MarkupEscaped(name) +
              " (failed)</td><td colspan=\"8\" class=\"l bad\">" +
              MarkupEscaped(input.value("error", "")) + "</td></tr>\n";
      ++i;
      continue;
    }
    const Json& truth = summary["truth"];
    const Json& pose = summary["pose"];
    html += "<tr><td class=\"l\"><a href=\"" + MarkupEscaped(name) + "/report.html\">" +
            MarkupEscaped(name) + "</a></td><td>" + std::to_string(summary.value("frames", 0)) +
            "</td><td" + (summary.value("frames_unreadable", 0) > 0 ? " class=\"bad\"" : "") + ">" +
            std::to_string(summary.value("frames_unreadable", 0)) + "</td><td>" +
            Percent(summary["detection"]["rate"]) + "</td><td>" +
            std::to_string(summary["detection"].value("lost_episodes", 0)) + "</td><td>" +
            (pose.is_null() ? "no camera" : Percent(pose["availability"])) + "</td><td>" +
            (truth.is_null() ? "—" : Number(truth["offset_px"]["mean"], 2)) + "</td><td>" +
            (truth.is_null() ? "—" : Number(truth["pose_translation_mm"]["mean"], 1)) +
            "</td><td id=\"wall-" + std::to_string(i) + "\">—</td></tr>\n";
    ++i;
  }
  html += "</table>\n";
  html += Canvas("chart-inputs", "Detection rate and pose availability per input");
  html += "<h2>Failed inputs</h2>\n" +
          (failed.empty() ? "<p>None.</p>\n" : "<ul>\n" + failed + "</ul>\n");
  html += "<h2>Skipped files</h2>\n" + List(run["skipped"], "None.");
  html += JsonBlock("oal-data", run);
  html += JsonBlock("oal-timing", Json(timing));
  html += std::string("<script>\n(function() {\n'use strict';") + kCommonScript + kIndexScript +
          "})();\n</script>\n";
  html += "</body>\n</html>\n";
  return html;
}

}  // namespace oal
