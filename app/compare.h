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

#include "detector/line.h"
#include "detector/options.h"
#include "io/json_io.h"

namespace oal {

/// What the target lines are: stripes (centre lines, two edges each) or single edges.
enum class TargetKind { kAuto, kStripes, kEdges };
/// "auto", "stripes", "edges".
std::string ToString(TargetKind kind);
/// The inverse; throws std::invalid_argument naming the accepted values.
TargetKind TargetKindFromString(const std::string& text);

/// One target line in one frame: what scoring and a user re-initialising a tracker see.
struct TargetLineTruth {
  int id = 0;             ///< the line's identity across frames (target index, CSV `line`)
  LineParams image_line;  ///< image (distorted) coordinates: distorted_fit or the CSV line
  LineParams ideal_line;  ///< undistorted pixels (JSON `ideal`); = image_line for CSV
  Point2d end_a, end_b;   ///< ends of the visible chord, image pixels
  double width_px = 0.0;  ///< stripe width, pixels (0: an edge or unknown)
};

/// The frame number a truth CSV row names for the frame read from `source` at 0-based
/// `position` in its input: the last run of digits in the file name (image.0001.pgm -> 1,
/// frame_0007.png -> 7, video.avi#12 -> 12), else `position`.
int FrameNumber(const std::string& source, int position);

/// A reference (truth) line in the coordinates of the lines it is matched with, and the ends
/// of its visible chord.
struct ReferenceLine {
  LineParams line;
  Point2d end_a, end_b;
};

/// A matched pair: indices into the references and the lines, the angle between the two
/// lines (degrees) and the offset (the larger distance of the chord ends from the line, px).
struct LineMatch {
  std::size_t reference = 0, line = 0;
  double angle_deg = 0.0, offset_px = 0.0;
};

/// Matches references and lines one to one, greedily by angle / max_angle_deg + offset /
/// max_offset_px (lowest first, ties in reference then line order), among the pairs within
/// both bounds (the `match` metric of the file comment). The matches in that order.
std::vector<LineMatch> MatchLines(const std::vector<ReferenceLine>& references,
                                  const std::vector<LineParams>& lines, double max_angle_deg,
                                  double max_offset_px);

/// Reads a truth CSV (format in the file comment): frame index -> its lines. Throws
/// std::runtime_error "FILE:LINE: ..." for a missing file or a malformed row. Chord ends are
/// left at zero (set per frame from the image size).
std::map<int, std::vector<TargetLineTruth>> LoadTruthCsv(const std::string& path);

/// The visible target lines of a frame_NNNN.json truth file (oalservo render). Throws
/// std::runtime_error naming the file if it is missing or malformed.
std::vector<TargetLineTruth> LoadTruthJson(const std::string& path);

/// A line detector or tracker under comparison. The runner calls, per frame:
///   Start(first frame, targets)   once, untimed (a tracker's initialisation)
///   Process(image, lines)         timed: the method's lines, best first, detector/line.h
///                                 convention, in image or (Undistorted()) undistorted pixels
///   AfterFrame(image, targets)    untimed: what a user does after seeing the result (a
///                                 tracker re-initialised after a failure)
/// `targets` are the frame's truth lines, or without truth our detector's first lines
/// (`from_truth` false). An oal-tracker method plugs in here.
class LineMethod {
 public:
  virtual ~LineMethod() = default;
  virtual std::string Name() const = 0;
  /// True when the lines are in undistorted pixels (scored against `ideal_line`).
  virtual bool Undistorted() const { return false; }
  virtual void Start(const vpImage<unsigned char>& /*image*/,
                     const std::vector<TargetLineTruth>& /*targets*/, bool /*from_truth*/) {}
  virtual void Process(const vpImage<unsigned char>& image, std::vector<LineParams>* lines) = 0;
  virtual void AfterFrame(const vpImage<unsigned char>& /*image*/,
                          const std::vector<TargetLineTruth>& /*targets*/, bool /*from_truth*/) {}
  /// Failures and re-initialisations so far; -1 for a method that is not a tracker.
  virtual int failures() const { return -1; }
  virtual int reinitialisations() const { return -1; }
};

/// vpMe settings of the vpMeLine method and its failure rule.
struct VpMeLineOptions {
  /// Search half-length along the normal of each moving edge, pixels, [1, 100]. Lines that
  /// move further between frames are lost (ViSP's default is 4; 15 follows slow and
  /// moderate motion).
  int range_px = 15;
  /// Likelihood threshold of a moving edge (vpMe::setThreshold; ViSP 3.5 default 10000 for
  /// its 5x5 masks), > 0. 10000 keeps edges of 40+ grey levels of contrast.
  double threshold = 10000.0;
  /// Distance between moving edges along the line, pixels, [1, 100].
  double sample_step_px = 5.0;
  /// With truth, a tracker further than either bound from its truth line has failed.
  double drift_angle_deg = 5.0;
  double drift_offset_px = 10.0;

  void Check() const;
};

struct CompareOptions {
  std::string input;        ///< what OpenImageSource opens; required
  std::string truth;        ///< "" (JSON next to the images), a directory, or a .csv
  std::string config_path;  ///< YAML for our detector; "" = defaults
  std::string camera_path;  ///< ViSP camera XML; "" = none
  std::string out_dir;      ///< "" = no files; else compare.md, .json and figures
  int lines = 0;            ///< K, lines scored per frame; 0 = truth count + 2, [0, 100]
  int max_frames = 0;       ///< 0 = all, >= 0
  TargetKind target_kind = TargetKind::kAuto;  ///< auto: from the truth widths, else config
  double max_angle_deg = 1.0;                  ///< match tolerance, degrees, > 0
  double max_offset_px = 2.0;                  ///< match tolerance, pixels, > 0
  double max_stripe_width_px = 0;  ///< edge pairing bound, pixels; 0: 1.5 x widest truth + 2
                                   ///< (30 without widths), >= 0
  int figures = 3;                 ///< compare_frame_NNNN.png written with --out, [0, 10]
  VpMeLineOptions me;

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
/// a missing or malformed input, truth, configuration or camera file.
/// `extra_methods` are run after the built-in ones (e.g. an oal-tracker).
CompareReport RunComparison(const CompareOptions& options,
                            std::vector<std::unique_ptr<LineMethod>> extra_methods = {});

/// The markdown table: one row per method.
std::string CompareMarkdown(const CompareReport& report);
/// The report as JSON (summary figures per method, not the per-frame lines).
Json CompareJson(const CompareReport& report);

}  // namespace oal
