// `pose --display` and `detect --display` in a real X server: Xvfb, the window photographed
// with ImageMagick's `import` while the command runs; without a display, a clear error
// before any output. Parts whose tools are missing skip, naming the package.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <thread>

#ifdef OAL_TEST_HAVE_X11
#include <X11/Xlib.h>
#include <X11/keysym.h>
#endif

#include "tests/app/command_test_util.h"
#include "tests/test_util.h"

namespace oal {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

bool HasProgram(const std::string& name) {
  return std::system(("command -v " + name + " >/dev/null 2>&1").c_str()) == 0;
}

int ExitCodeOf(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string Oalservo() {
  return std::string("'") + OAL_OALSERVO_PATH + "'";
}

// An Xvfb server for the test's life, on a display number it picks itself and tells once it
// accepts clients (-displayfd), kept up between clients (-noreset: a server resetting after
// its last client refuses the next one for a moment).
class VirtualDisplay {
 public:
  VirtualDisplay() {
    int ready[2];
    if (::pipe(ready) != 0) return;
    pid_ = ::fork();
    if (pid_ == 0) {
      ::close(ready[0]);
      const std::string fd = std::to_string(ready[1]);
      ::execlp("Xvfb", "Xvfb", "-displayfd", fd.c_str(), "-screen", "0", "1024x768x24", "-nolisten",
               "tcp", "-noreset", static_cast<char*>(nullptr));
      ::_exit(127);
    }
    ::close(ready[1]);
    pollfd wait{ready[0], POLLIN, 0};
    std::string number;
    char c = 0;
    while (::poll(&wait, 1, 10000) > 0 && ::read(ready[0], &c, 1) == 1 && c != '\n') number += c;
    ::close(ready[0]);
    if (!number.empty()) name_ = ":" + number;
  }
  ~VirtualDisplay() {
    if (pid_ > 0) {
      ::kill(pid_, SIGTERM);
      ::waitpid(pid_, nullptr, 0);
    }
  }
  VirtualDisplay(const VirtualDisplay&) = delete;
  VirtualDisplay& operator=(const VirtualDisplay&) = delete;

  const std::string& name() const { return name_; }
  bool Ready() const { return !name_.empty(); }

 private:
  std::string name_;
  pid_t pid_ = -1;
};

// Pixels of the strong colours the annotation draws (the rendered scene is grey).
int ColouredPixels(const cv::Mat& bgr) {
  int count = 0;
  for (int r = 0; r < bgr.rows; ++r) {
    for (int c = 0; c < bgr.cols; ++c) {
      const cv::Vec3b p = bgr.at<cv::Vec3b>(r, c);
      const int high = std::max({p[0], p[1], p[2]}), low = std::min({p[0], p[1], p[2]});
      count += high - low > 120;
    }
  }
  return count;
}

TEST(Display, WithoutADisplayPoseAndDetectSayWhyBeforeAnyOutput) {
  test::TestDir dir;
  ASSERT_EQ(
      ExitCodeOf(Oalservo() + " render --count 2 --out '" + dir / "frames" + "' >/dev/null 2>&1"),
      0);
  for (const char* command : {"pose", "detect"}) {
    SCOPED_TRACE(command);
    const std::string out = dir / (std::string(command) + ".jsonl");
    const std::string err = dir / "err.txt";
    EXPECT_EQ(ExitCodeOf("env -u DISPLAY " + Oalservo() + " " + command + " '" + dir / "frames" +
                         "' --display --out '" + out + "' 2>'" + err + "'"),
              1);
    const std::string said = test::ReadText(err);
    EXPECT_THAT(said, HasSubstr("oalservo " + std::string(command) + ": error: --display: "));
    EXPECT_THAT(said, HasSubstr("$DISPLAY"));
    EXPECT_FALSE(fs::exists(out));
  }
  // evaluate shows one input evaluated alone.
  EXPECT_EQ(ExitCodeOf(Oalservo() + " evaluate '" + dir / "frames" + "' '" + dir / "frames" +
                       "' --display --out '" + dir / "ev" + "' 2>'" + dir / "err.txt" + "'"),
            2);
  EXPECT_THAT(test::ReadText(dir / "err.txt"), HasSubstr("--display shows one input"));
  // A rate out of range is refused by the command line (a usage error).
  EXPECT_EQ(ExitCodeOf(Oalservo() + " pose '" + dir / "frames" +
                       "' --display --display-fps 0 >/dev/null 2>&1"),
            2);
}

TEST(Display, PoseDetectAndEvaluateShowEachFrameInAWindowAndEndWithTheInput) {
  if (!HasProgram("Xvfb")) GTEST_SKIP() << "no Xvfb (Debian's xvfb)";
  if (!HasProgram("import")) GTEST_SKIP() << "no import (Debian's imagemagick)";
  test::TestDir dir;
  ASSERT_EQ(ExitCodeOf(Oalservo() + " render --count 30 --seed 4 --out '" + dir / "frames" +
                       "' >/dev/null 2>&1"),
            0);
  const VirtualDisplay display;
  ASSERT_TRUE(display.Ready()) << "Xvfb " << display.name() << " did not start";
  for (const char* command : {"pose", "detect", "evaluate"}) {
    SCOPED_TRACE(command);
    const bool evaluate = std::string(command) == "evaluate";
    const std::string out = dir / (std::string(command) + (evaluate ? "" : ".jsonl"));
    // 30 frames at 10 a second: the window is photographed until it shows a frame.
    std::thread run([&] {
      EXPECT_EQ(ExitCodeOf("DISPLAY=" + display.name() + " " + Oalservo() + " " + command + " '" +
                           dir / "frames" + "' --display --display-fps 10 --out '" + out + "' 2>'" +
                           dir / "err.txt" + "'"),
                0)
          << test::ReadText(dir / "err.txt");
    });
    const std::string shot = dir / (std::string(command) + "-window.png");
    cv::Mat screen;
    for (int attempt = 0; attempt < 20; ++attempt) {
      std::this_thread::sleep_for(std::chrono::milliseconds(250));
      if (ExitCodeOf("import -display " + display.name() + " -window root '" + shot +
                     "' >/dev/null 2>&1") != 0) {
        continue;
      }
      screen = cv::imread(shot, cv::IMREAD_COLOR);
      if (!screen.empty() && ColouredPixels(screen) > 2000) break;
    }
    run.join();
    ASSERT_FALSE(screen.empty()) << "no screenshot of " << display.name();
    // The frame with its lines drawn in colour, and the caption in white under it.
    EXPECT_GT(ColouredPixels(screen), 2000);
    const cv::Mat caption = screen(cv::Rect(0, 480, 640, 40));
    EXPECT_GT(cv::countNonZero(caption.reshape(1) > 200), 100);
    // Every frame was processed and written, the window notwithstanding.
    EXPECT_EQ(test::ReadLines(evaluate ? out + "/frames/frames.jsonl" : out).size(), 30u);
  }
}

#ifdef OAL_TEST_HAVE_X11
// Sends a key press (q) to the top-level window whose title begins with `title` on the X
// display `display_name`, as a user's key would arrive; false when there is no such window.
bool PressKeyIn(const std::string& display_name, const std::string& title) {
  ::Display* display = XOpenDisplay(display_name.c_str());
  if (display == nullptr) return false;
  const ::Window root = DefaultRootWindow(display);
  ::Window root_return = 0, parent = 0, *children = nullptr;
  unsigned int count = 0;
  bool sent = false;
  if (XQueryTree(display, root, &root_return, &parent, &children, &count) != 0) {
    for (unsigned int i = 0; i < count && !sent; ++i) {
      char* name = nullptr;
      if (XFetchName(display, children[i], &name) == 0 || name == nullptr) continue;
      if (std::string(name).rfind(title, 0) == 0) {
        XKeyEvent key{};
        key.type = KeyPress;
        key.display = display;
        key.window = children[i];
        key.root = root;
        key.same_screen = True;
        key.keycode = XKeysymToKeycode(display, XK_q);
        sent = XSendEvent(display, children[i], True, KeyPressMask,
                          reinterpret_cast<XEvent*>(&key)) != 0;
      }
      XFree(name);
    }
    if (children != nullptr) XFree(children);
  }
  XFlush(display);
  XCloseDisplay(display);
  return sent;
}

TEST(Display, AKeyInTheWindowStopsKeepingWhatWasWritten) {
  if (!HasProgram("Xvfb")) GTEST_SKIP() << "no Xvfb (Debian's xvfb)";
  test::TestDir dir;
  ASSERT_EQ(ExitCodeOf(Oalservo() + " render --count 100 --seed 5 --out '" + dir / "frames" +
                       "' >/dev/null 2>&1"),
            0);
  const VirtualDisplay display;
  ASSERT_TRUE(display.Ready());
  const std::string out = dir / "poses.jsonl";
  // 100 frames at 5 a second: 20 s unless the key stops it.
  std::atomic<bool> ended{false};
  std::thread run([&] {
    EXPECT_EQ(
        ExitCodeOf("DISPLAY=" + display.name() + " " + Oalservo() + " pose '" + dir / "frames" +
                   "' --display --display-fps 5 --out '" + out + "' 2>'" + dir / "err.txt" + "'"),
        0)
        << test::ReadText(dir / "err.txt");
    ended = true;
  });
  // The key is pressed again until the command ends: a window that is up may not listen to
  // keys yet (a loaded machine), and a user would press again too.
  bool pressed = false;
  while (!ended) {
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
    pressed = PressKeyIn(display.name(), "oalservo pose") || pressed;
  }
  run.join();
  ASSERT_TRUE(pressed) << "no window titled 'oalservo pose' on " << display.name();
  const std::size_t written = test::ReadLines(out).size();
  EXPECT_GT(written, 0u);
  EXPECT_LT(written, 100u);
  EXPECT_THAT(test::ReadText(dir / "err.txt"),
              HasSubstr("stopped from the window after " + std::to_string(written) + " frames"));
}
#endif

}  // namespace
}  // namespace oal
