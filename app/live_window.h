// A live ViSP window (vpDisplayX) that shows annotated frames: `servo`, and `pose` and
// `detect` with --display. A click in it or a key pressed asks the command to stop.
#pragma once

#include <atomic>
#include <chrono>
#include <memory>
#include <opencv2/core/mat.hpp>
#include <string>

namespace oal {

/// True when a window may be tried: this ViSP has X11 and $DISPLAY is set (the X server may
/// still be unreachable: LiveWindow's constructor says so).
bool CanOpenLiveWindow();

/// Why no window can be tried (CanOpenLiveWindow() false), in the user's words.
std::string NoLiveWindowReason();

class LiveWindow {
 public:
  /// Opens the window now, blank, `width` x `height` (the frames' size), titled `title`, so
  /// that a missing or unreachable X display is found before any work. Throws
  /// std::runtime_error saying why when it cannot be opened (NoLiveWindowReason(), or the X
  /// display named by $DISPLAY that does not answer).
  LiveWindow(int width, int height, const std::string& title);
  ~LiveWindow();
  LiveWindow(const LiveWindow&) = delete;
  LiveWindow& operator=(const LiveWindow&) = delete;

  /// Shows a BGR frame (the window takes its size).
  void Show(const cv::Mat& bgr);
  /// True once the user has clicked in the window or pressed a key in it.
  bool StopAsked();
  /// Waits for a click or a key in the window (for the user to look at the last frame), or
  /// until `*interrupt` is set (Ctrl-C).
  void WaitForClick(const std::atomic<bool>* interrupt);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// A LiveWindow fed frame by frame by `pose` or `detect`: each annotated frame with a caption
/// (what the command says of it, the frames per second, how to quit); frames from files are
/// paced to `paced_fps`, a camera's shown as they come.
class LiveView {
 public:
  /// Opens the window now (throws as LiveWindow does). `paced_fps` > 0.
  LiveView(const std::string& title, double paced_fps);

  /// Shows `annotated` (BGR) with `caption` below it; `live`: the frame came from a camera
  /// (not paced). False once the user asked to stop (a click or a key).
  bool Show(cv::Mat annotated, const std::string& caption, bool live);

 private:
  LiveWindow window_;
  double paced_fps_;
  std::chrono::steady_clock::time_point last_shown_{};
  double shown_fps_ = 0.0;  // smoothed
};

}  // namespace oal
