// `oalservo compare`: line detectors and trackers head to head on the same frames (ours,
// vpMeLine, OpenCV's HoughLines, HoughLinesP, LSD and FLD, and our target tracker), each timed
// around its own call and scored against the same centre-line truth. The methods, how edges
// become centre lines, the truth formats and the metrics: docs/COMPARE.md.
#pragma once

#include <visp3/core/vpCameraParameters.h>
#include <visp3/core/vpImage.h>

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "base/field_names.h"
#include "detector/line.h"
#include "detector/options.h"
#include "eval/lines/line_method.h"
#include "eval/lines/oal_methods.h"
#include "eval/lines/vp_me_line_method.h"
#include "io/json_io.h"

namespace oal {

/// What the target lines are: stripes (centre lines, two edges each) or single edges.
enum class TargetKind { kAuto, kStripes, kEdges };
/// "auto", "stripes", "edges".
std::string ToString(TargetKind kind);
/// The inverse; throws std::invalid_argument naming the accepted values.
TargetKind TargetKindFromString(const std::string& text);

struct CompareOptions {
  std::string input;        ///< what OpenImageSource opens; required
  std::string truth;        ///< "" (JSON next to the images), a directory, or a .csv
  std::string camera_path;  ///< ViSP camera XML; "" = none
  std::string out_dir;      ///< "" = no files; else compare.md, .json and figures
  int lines = 0;            ///< K, lines scored per frame; 0 = truth count + 2, [0, 100]
  int max_frames = 0;       ///< 0 = all, >= 0
  TargetKind target_kind = TargetKind::kAuto;  ///< auto: from the detector's polarity
  double max_angle_deg = 1.0;                  ///< match tolerance, degrees, > 0
  double max_offset_px = 2.0;                  ///< match tolerance, pixels, > 0
  double max_stripe_width_px = 0;  ///< edge pairing bound, pixels; 0: 1.5 x widest truth + 2
                                   ///< (30 without widths), >= 0
  int figures = 3;                 ///< compare_frame_NNNN.png written with --out, [0, 10]
  VpMeLineOptions me;
  /// Our detector, and the target tracker when setup.target is a four-line target (with a
  /// camera file: it needs the camera for the pose).
  TrackerSetup setup;
  /// How the caller names these options to its user ("camera_path" -> "--camera"), in the
  /// warnings and messages; unnamed ones keep their own names.
  FieldNames names;

  void Check() const;
};

/// What one method did over all frames.
struct MethodResult {
  std::string name;
  std::string reference;  ///< "ideal", "distorted_fit", "csv" or "none"
  int frames = 0;
  int frames_all_found = 0;
  int truth_lines = 0;  ///< summed over frames
  int found_lines = 0;
  int spurious_lines = 0;               ///< summed over frames (without truth: the lines output)
  std::vector<double> angle_error_deg;  ///< matched lines
  std::vector<double> offset_error_px;
  std::vector<double> time_us;           ///< per frame
  std::vector<double> time_us_per_line;  ///< per frame, divided by the target count
  int failures = -1;                     ///< trackers only
  int reinitialisations = -1;
  std::vector<int> missed_frames;              ///< frames where some truth line was not found
  std::vector<int> missed_per_frame;           ///< truth lines not found, per frame
  std::vector<std::vector<LineParams>> lines;  ///< scored lines per frame (for figures)
};

struct CompareReport {
  CompareOptions options;
  std::string truth_source;  ///< "json", "csv" or "none"
  TargetKind target_kind = TargetKind::kStripes;
  double max_stripe_width_px = 0.0;  ///< as used
  int frames = 0;
  int width = 0, height = 0;
  std::vector<MethodResult> methods;
  std::vector<std::string> figures;  ///< written figure paths
  std::vector<std::string> warnings;
};

/// Runs every method on every frame of options.input and scores it. With options.out_dir
/// writes compare.md, compare.json and the figures there (each atomically, all or none).
/// Throws std::invalid_argument for bad options and std::runtime_error naming the file for
/// a missing or malformed input, truth or camera file.
/// `extra_methods` are run after the built-in ones (e.g. an oal-tracker).
CompareReport RunComparison(const CompareOptions& options,
                            std::vector<std::unique_ptr<LineMethod>> extra_methods = {});

/// The markdown table: one row per method.
std::string CompareMarkdown(const CompareReport& report);
/// The report as JSON (summary figures per method, not the per-frame lines).
Json CompareJson(const CompareReport& report);

}  // namespace oal
