#include "app/live_window.h"

#include <visp3/core/vpConfig.h>
#include <visp3/core/vpDisplay.h>
#include <visp3/core/vpException.h>
#include <visp3/core/vpImage.h>
#include <visp3/core/vpImageConvert.h>
#include <visp3/core/vpRGBa.h>
#ifdef VISP_HAVE_X11
#include <visp3/gui/vpDisplayX.h>
#endif

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <vector>

#include "base/format.h"

namespace oal {

bool CanOpenLiveWindow() {
#ifdef VISP_HAVE_X11
  const char* display = std::getenv("DISPLAY");
  return display != nullptr && *display != '\0';
#else
  return false;
#endif
}

std::string NoLiveWindowReason() {
#ifdef VISP_HAVE_X11
  return "no window can be opened (no X11 display: $DISPLAY is unset)";
#else
  return "no window can be opened (this ViSP was built without X11)";
#endif
}

struct LiveWindow::Impl {
  vpImage<vpRGBa> image;
  std::string title;
#ifdef VISP_HAVE_X11
  vpDisplayX display;
#endif
  bool open = false;
  bool stop = false;

  // Opens the window on `image` (its size); throws std::runtime_error saying why it cannot.
  void Open() {
#ifdef VISP_HAVE_X11
    try {
      display.init(image, 0, 0, title);
    } catch (const vpException& error) {
      const char* name = std::getenv("DISPLAY");
      throw std::runtime_error(
          "cannot open a window on the X display '" + std::string(name != nullptr ? name : "") +
          "' ($DISPLAY): " + error.getMessage() + " (is the X server running and reachable?)");
    }
    open = true;
#endif
  }

  // A click or a key since the last look.
  bool Asked() {
    if (!open) return false;
    const bool clicked = vpDisplay::getClick(image, false);
    const bool key = vpDisplay::getKeyboardEvent(image, false);
    return clicked || key;
  }
};

LiveWindow::LiveWindow(int width, int height, const std::string& title) {
  if (!CanOpenLiveWindow()) throw std::runtime_error(NoLiveWindowReason());
  impl_ = std::make_unique<Impl>();
  impl_->title = title;
  impl_->image.init(static_cast<unsigned>(height), static_cast<unsigned>(width), vpRGBa(0));
  impl_->Open();
}

LiveWindow::~LiveWindow() = default;

void LiveWindow::Show(const cv::Mat& bgr) {
#ifdef VISP_HAVE_X11
  if (impl_->open && (static_cast<int>(impl_->image.getWidth()) != bgr.cols ||
                      static_cast<int>(impl_->image.getHeight()) != bgr.rows)) {
    vpDisplay::close(impl_->image);  // reopened below at the frame's size
    impl_->open = false;
  }
  vpImageConvert::convert(bgr, impl_->image);
  if (!impl_->open) impl_->Open();
  vpDisplay::display(impl_->image);
  vpDisplay::flush(impl_->image);
#else
  (void)bgr;
#endif
}

bool LiveWindow::StopAsked() {
  if (!impl_->stop) impl_->stop = impl_->Asked();
  return impl_->stop;
}

void LiveWindow::WaitForClick(const std::atomic<bool>* interrupt) {
  while (impl_->open && !impl_->Asked()) {
    if (interrupt != nullptr && interrupt->load()) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

namespace {

// `text` in lines that fit `width_px` in the caption's font, broken between words.
std::vector<std::string> WrappedToWidth(const std::string& text, int width_px) {
  std::vector<std::string> lines(1);
  std::istringstream words(text);
  for (std::string word; words >> word;) {
    const std::string longer = lines.back().empty() ? word : lines.back() + " " + word;
    int baseline = 0;
    const int width =
        cv::getTextSize(longer, cv::FONT_HERSHEY_SIMPLEX, 0.5, 1, &baseline).width + 12;
    if (width > width_px && !lines.back().empty()) {
      lines.push_back(word);
    } else {
      lines.back() = longer;
    }
  }
  return lines;
}

}  // namespace

LiveView::LiveView(const std::string& title, double paced_fps)
    : window_(640, 480, title + " (click or a key to quit)"), paced_fps_(paced_fps) {}

bool LiveView::Show(cv::Mat annotated, const std::string& caption, bool live) {
  using Clock = std::chrono::steady_clock;
  if (!live && last_shown_ != Clock::time_point{}) {
    std::this_thread::sleep_until(last_shown_ +
                                  std::chrono::duration_cast<Clock::duration>(
                                      std::chrono::duration<double>(1.0 / paced_fps_)));
  }
  const Clock::time_point now = Clock::now();
  if (last_shown_ != Clock::time_point{}) {
    const double fps =
        1.0 / std::max(1e-6, std::chrono::duration<double>(now - last_shown_).count());
    shown_fps_ = shown_fps_ == 0.0 ? fps : 0.9 * shown_fps_ + 0.1 * fps;
  }
  last_shown_ = now;
  // The caption in a band under the frame: white on black, a line each.
  const std::string fps = shown_fps_ > 0.0 ? Fixed(shown_fps_, 1) + " frames/s" : "";
  std::vector<std::string> lines = WrappedToWidth(caption, annotated.cols);
  lines.push_back(fps + (fps.empty() ? "" : "   ") + "click or a key in the window: quit");
  constexpr int kLineHeight = 20;
  cv::Mat shown(annotated.rows + kLineHeight * static_cast<int>(lines.size()) + 6, annotated.cols,
                CV_8UC3, cv::Scalar(0, 0, 0));
  annotated.copyTo(shown(cv::Rect(0, 0, annotated.cols, annotated.rows)));
  for (std::size_t i = 0; i < lines.size(); ++i) {
    cv::putText(shown, lines[i],
                cv::Point(6, annotated.rows + kLineHeight * (static_cast<int>(i) + 1)),
                cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  }
  window_.Show(shown);
  return !window_.StopAsked();
}

}  // namespace oal
