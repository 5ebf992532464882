// What `oalservo servo` shows and writes besides the table: the pose-error plot, the
// annotated frames of a headless run and the live vpDisplayX window.
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

#include <atomic>
#include <filesystem>
#include <memory>
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

/// True when a window may be tried: this ViSP has X11 and $DISPLAY is set (the X server may
/// still be unreachable: ServoWindow's constructor says so).
bool CanOpenServoWindow();

/// A vpDisplayX window that shows annotated frames; a click in it asks the loop to stop.
class ServoWindow {
 public:
  /// Opens the window now, blank, `width` x `height` (the frames' size), so that a missing or
  /// unreachable X display is found before the robot is touched. Throws std::runtime_error
  /// saying why when it cannot be opened.
  ServoWindow(int width, int height);
  ~ServoWindow();
  ServoWindow(const ServoWindow&) = delete;
  ServoWindow& operator=(const ServoWindow&) = delete;

  /// Shows a BGR frame (the window takes its size).
  void Show(const cv::Mat& bgr);
  /// True once the user has clicked in the window.
  bool StopClicked();
  /// Waits for a click in the window (for the user to look at the last frame), or until
  /// `*interrupt` is set (Ctrl-C).
  void WaitForClick(const std::atomic<bool>* interrupt);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace oal
