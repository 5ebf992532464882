// `oalservo demo`: one rendered frame, its lines detected and compared with the truth. By
// default an A3 sheet lying on a photograph of a bench among other sheets and tools, found
// with the target tracker (the sheet's middle cell, borders on its plane) and its pose
// estimated; `--target four-line-board` is the paper's condition, the 2 m board filling the
// view of a cheap wide lens, scanned on the image's borders. Writes DIR/frame.png (raw),
// DIR/demo.png (lines drawn), DIR/lines.json and prints a table.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

namespace oal {

struct DemoCommandOptions {
  std::string out_dir = "out/demo";     ///< created if missing
  std::uint64_t seed = 1;               ///< pose and noise
  std::string target = "four-line-a3";  ///< one of TargetNames() (scene/scene.h)

  void Check() const;
};

/// How well one target line was found.
struct DemoMatch {
  int truth_index = 0;      ///< index of the target line (line truth_index + 1 in the docs)
  int detected_index = -1;  ///< index in the detector's output; -1: not found
  double angle_error_deg = 0.0;
  /// Largest distance of the detected line from the true line over the visible chord,
  /// undistorted pixels.
  double max_offset_px = 0.0;
};

struct DemoReport {
  int detected = 0;  ///< lines the detector returned
  double time_us = 0.0;
  std::vector<DemoMatch> matches;  ///< one per visible target line
  /// The target tracker's status ("ok", "not-found" ...) for a four-line target; empty for
  /// the two-line board (detected on the image's borders, no pose).
  std::string pose_status;
};

/// Renders, detects, compares and writes the files; prints the table to `out` (target lines
/// numbered 1-4, as in the docs). Throws std::runtime_error if `out` fails (disk full).
DemoReport RunDemoScene(const DemoCommandOptions& options, std::ostream& out);

/// `oalservo demo ...`; argv[0] is "demo".
int RunDemo(int argc, char** argv);

}  // namespace oal
