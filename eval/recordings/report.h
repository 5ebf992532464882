// The HTML reports of `oalservo evaluate`: one page per input and an index, each a single
// self-contained file (no network, no other file): the data as JSON blocks, the plots drawn
// in the browser by Chart.js (Debian's libjs-chart.js, inlined), the thumbnails as base64
// JPEG.
//
// Page structure (what tests and the headless-browser check rely on):
//   <script type="application/json" id="oal-data">     deterministic data (summary, series)
//   <script type="application/json" id="oal-timing">   timings (differ from run to run)
//   <canvas class="oal-chart" id="chart-...">           one per plot; the page script sets
//                                                       data-drawn="1" on each after Chart
//                                                       created it, and data-charts="N" on
//                                                       <body> when all N are drawn
#pragma once

#include <string>
#include <vector>

#include "io/json_io.h"

namespace oal {

/// Where Chart.js is read from: $OAL_CHARTJS if set, else Debian's
/// /usr/share/javascript/chart.js/chart.min.js.
std::string ChartJsPath();

/// The text of Chart.js (ChartJsPath()). Throws std::runtime_error saying which package to
/// install when it is missing.
std::string LoadChartJs();

/// The worst frames shown are at least this many frames apart (one bad stretch, one thumbnail).
constexpr int kThumbnailSpacingFrames = 10;

/// A worst frame's thumbnail for the report.
struct Thumbnail {
  int frame = 0;
  std::string why;  ///< what made it bad, for the caption
  std::vector<unsigned char> jpeg;
};

/// The page of one input. `summary` is its summary.json, `series` the per-frame values the
/// plots show (evaluate.cpp: frame, held, pose_ok, rho, theta_deg, offset_px, angle_deg,
/// pose_t_mm, pose_r_deg), `timing` its timing statistics and per-frame times.
std::string InputReportHtml(const Json& summary, const Json& series, const Json& timing,
                            const std::vector<Thumbnail>& thumbnails, const std::string& chart_js);

/// The index of a run: one row per input (linking NAME/report.html), the failed inputs with
/// their error, the skipped files, and a plot of detection rate and pose availability.
/// `inputs` are {input, name, status, error, summary}; `timing` the inputs' timing.json
/// (null for failed ones), in the same order.
std::string IndexHtml(const Json& run, const std::vector<Json>& timing,
                      const std::string& chart_js);

}  // namespace oal
