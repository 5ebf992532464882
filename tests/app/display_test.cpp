// `pose --display` and `detect --display` in a real X server: Xvfb, the window photographed
// with ImageMagick's `import` while the command runs; without a display, a clear error
// before any output. Parts whose tools are missing skip, naming the package.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <thread>

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

// An Xvfb server on its own display number for the test's life.
class VirtualDisplay {
 public:
  VirtualDisplay() : name_(":" + std::to_string(90 + ::getpid() % 800)) {
    pid_ = ::fork();
    if (pid_ == 0) {
      ::execlp("Xvfb", "Xvfb", name_.c_str(), "-screen", "0", "1024x768x24", "-nolisten", "tcp",
               static_cast<char*>(nullptr));
      ::_exit(127);
    }
    // Ready once a client can connect.
    for (int i = 0; i < 100 && !Ready(); ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
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
  // Xvfb listens on its socket once it is ready.
  bool Ready() const { return fs::exists("/tmp/.X11-unix/X" + name_.substr(1)); }

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
  // A rate out of range is refused by the command line (a usage error).
  EXPECT_EQ(ExitCodeOf(Oalservo() + " pose '" + dir / "frames" +
                       "' --display --display-fps 0 >/dev/null 2>&1"),
            2);
}

TEST(Display, PoseAndDetectShowEachFrameInAWindowAndEndWithTheInput) {
  if (!HasProgram("Xvfb")) GTEST_SKIP() << "no Xvfb (Debian's xvfb)";
  if (!HasProgram("import")) GTEST_SKIP() << "no import (Debian's imagemagick)";
  test::TestDir dir;
  ASSERT_EQ(ExitCodeOf(Oalservo() + " render --count 30 --seed 4 --out '" + dir / "frames" +
                       "' >/dev/null 2>&1"),
            0);
  const VirtualDisplay display;
  ASSERT_TRUE(display.Ready()) << "Xvfb " << display.name() << " did not start";
  for (const char* command : {"pose", "detect"}) {
    SCOPED_TRACE(command);
    const std::string out = dir / (std::string(command) + ".jsonl");
    // 30 frames at 15 a second: the window is photographed a second in.
    std::thread run([&] {
      EXPECT_EQ(ExitCodeOf("DISPLAY=" + display.name() + " " + Oalservo() + " " + command + " '" +
                           dir / "frames" + "' --display --display-fps 15 --out '" + out + "' 2>'" +
                           dir / "err.txt" + "'"),
                0)
          << test::ReadText(dir / "err.txt");
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(1000));
    const std::string shot = dir / (std::string(command) + "-window.png");
    const int taken = ExitCodeOf("import -display " + display.name() + " -window root '" + shot +
                                 "' >/dev/null 2>&1");
    run.join();
    ASSERT_EQ(taken, 0);
    const cv::Mat screen = cv::imread(shot, cv::IMREAD_COLOR);
    ASSERT_FALSE(screen.empty());
    // The frame with its lines drawn in colour, and the caption in white under it.
    EXPECT_GT(ColouredPixels(screen), 2000);
    const cv::Mat caption = screen(cv::Rect(0, 480, 640, 40));
    EXPECT_GT(cv::countNonZero(caption.reshape(1) > 200), 100);
    // Every frame was processed and written, the window notwithstanding.
    EXPECT_EQ(test::ReadLines(out).size(), 30u);
  }
}

}  // namespace
}  // namespace oal
