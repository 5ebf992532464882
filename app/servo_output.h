// What `oalservo servo` writes besides the table: the pose-error plot and the annotated
// frames of a headless run (the live window is app/live_window.h).
//
//   DIR/servo.csv          one row per iteration (WriteServoCsv, loop/servo_loop.h)
//   DIR/servo-error.png    translation (mm) and rotation (deg) error per iteration, estimated
//                          and (simulation) true, against the tolerances, drawn by gnuplot
//   DIR/frames/iter_NNNN.png  each iteration's frame with the identified lines 1-4, the
//                          target frame and the errors (no window, output.save_frames); a
//                          run, once its source and robot are open, first removes the
//                          iter_*.png an earlier run left there
// Every file is written atomically. The directory is checked writable before the robot is
// touched (CheckWritableDirectory); an earlier run's files are replaced only by a run that
// began (the robot connected).
#pragma once

#include <filesystem>
#include <opencv2/core/mat.hpp>
#include <string>

#include "app/servo_run.h"

namespace oal {

/// The gnuplot script that draws `report`'s errors per iteration (estimated, and true in
/// simulation, with the law's tolerances; log scale) into the PNG `png`.
std::string ServoPlotScript(const ServoRunReport& report, const ServoOptions& law,
                            const std::filesystem::path& png);
/// Runs gnuplot (Debian's gnuplot-nox) on ServoPlotScript; `path` appears only once complete.
/// Throws std::runtime_error with gnuplot's message when it is missing or fails.
void WriteServoPlot(const ServoRunReport& report, const ServoOptions& law,
                    const std::filesystem::path& path);

/// The frame of one iteration annotated: the pose's lines, corners and target frame
/// (AnnotatePose) and a caption with the iteration, the errors and the status.
cv::Mat AnnotateServoFrame(const ServoFrame& frame);

/// Makes sure `dir` can take output files before any work: creates it (and its parents) if
/// missing, then creates and removes a file in it. Throws std::runtime_error naming `what`
/// (e.g. "output directory (--out)"), the directory and the reason.
void CheckWritableDirectory(const std::filesystem::path& dir, const std::string& what);

}  // namespace oal
