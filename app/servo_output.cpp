#include "app/servo_output.h"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iomanip>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <vector>

#include "base/format.h"
#include "detector/lens.h"
#include "io/annotate.h"
#include "io/atomic_file.h"

namespace oal {
namespace {

const cv::Scalar kWhite(255, 255, 255), kBlack(0, 0, 0);

// A string for a gnuplot single-quoted literal ('' is a quote).
std::string GnuplotQuoted(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) quoted += c == '\'' ? std::string("''") : std::string(1, c);
  return quoted + "'";
}

// A word for /bin/sh, single-quoted.
std::string ShellQuoted(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

// Errors as "nan": gnuplot leaves such points out.
std::string Value(double value) {
  return std::isfinite(value) ? Number(value, 9) : "nan";
}

// Frames the run took (the row after a stop has no frame).
int FramesOf(const ServoRunReport& report) {
  return static_cast<int>(
      std::count_if(report.iterations.begin(), report.iterations.end(),
                    [](const ServoIteration& row) { return row.status != "stopped"; }));
}

}  // namespace

std::string ServoPlotScript(const ServoRunReport& report, const ServoOptions& law,
                            const std::filesystem::path& png) {
  bool truth = false;
  for (const ServoIteration& row : report.iterations) {
    truth = truth || std::isfinite(row.true_translation_error_mm);
  }
  std::ostringstream gp;
  gp << "$errors << EOD\n";
  for (const ServoIteration& row : report.iterations) {
    gp << row.iteration << ' ' << Value(row.translation_error_mm) << ' '
       << Value(row.rotation_error_deg) << ' ' << Value(row.true_translation_error_mm) << ' '
       << Value(row.true_rotation_error_deg) << '\n';
  }
  gp << "EOD\n"
     << "set terminal pngcairo size 800,640 font 'sans,10'\n"
     << "set output " << GnuplotQuoted(png.string()) << "\n"
     << "set multiplot layout 2,1 title "
     << GnuplotQuoted("oalservo servo: " + ToString(law.mode) + " law, " + ToString(report.status) +
                      " after " + std::to_string(report.moves) +
                      (report.moves == 1 ? " move (" : " moves (") +
                      std::to_string(FramesOf(report)) + " frames)")
     << "\n"
     << "set logscale y\nset grid\nset key top right\nset xlabel 'frame'\n"
     << "set xtics 1\nset xrange [-0.3:" << std::max<std::size_t>(report.iterations.size(), 2) - 0.7
     << "]\n";
  // The frames the loop held at (nothing commanded), shaded in both panels.
  int held = 0;
  for (const ServoIteration& row : report.iterations) {
    if (row.status != "held") continue;
    gp << "set object " << ++held << " rect from " << row.iteration - 0.5 << ", graph 0 to "
       << row.iteration + 0.5 << ", graph 1 behind fc rgb '#f2d0d0' fs solid noborder\n";
  }
  if (held > 0) {
    gp << "set label 'shaded: held, nothing commanded' at graph 0.01, graph 0.04 front\n";
  }
  const auto panel = [&](const char* label, int estimated, int true_column, double tolerance) {
    gp << "set ylabel " << GnuplotQuoted(label) << "\n"
       << "plot $errors using 1:" << estimated
       << " with linespoints lw 2 pt 7 title 'estimated (what the law sees)'";
    if (truth) {
      gp << ", $errors using 1:" << true_column
         << " with linespoints lw 2 pt 5 title 'true (simulation)'";
    }
    gp << ", " << Value(tolerance) << " with lines dt 2 lc rgb 'black' title 'tolerance'\n";
  };
  panel("translation error to the goal (mm)", 2, 4, law.translation_tolerance_m * 1e3);
  panel("rotation error to the goal (deg)", 3, 5, law.rotation_tolerance_deg);
  gp << "unset multiplot\n";
  return gp.str();
}

void WriteServoPlot(const ServoRunReport& report, const ServoOptions& law,
                    const std::filesystem::path& path) {
  // gnuplot draws into a temporary file that replaces `path` only when it succeeded.
  const std::filesystem::path temp = TempPathFor(path);
  const std::filesystem::path script = TempPathFor(path.string() + ".gp");
  WriteFileAtomically(script, ServoPlotScript(report, law, temp));
  const std::string command = "gnuplot " + ShellQuoted(script.string()) + " 2>&1";
  std::string output;
  int status = -1;
  if (FILE* pipe = popen(command.c_str(), "r")) {
    char buffer[256];
    while (std::fgets(buffer, sizeof(buffer), pipe) != nullptr) output += buffer;
    status = pclose(pipe);
  }
  RemoveQuietly(script);
  std::error_code error;
  if (status != 0 || !std::filesystem::is_regular_file(temp, error)) {
    RemoveQuietly(temp);
    throw std::runtime_error("cannot plot " + path.string() + " with gnuplot (" +
                             (status == -1 || (WIFEXITED(status) && WEXITSTATUS(status) == 127)
                                  ? std::string("gnuplot not found: install gnuplot-nox")
                                  : "exit status " + std::to_string(status)) +
                             (output.empty() ? "" : "): " + output.substr(0, 300)) + ")");
  }
  std::filesystem::rename(temp, path);
}

cv::Mat AnnotateServoFrame(const ServoFrame& frame) {
  const std::optional<Lens> undistorted_by =
      frame.lines_undistorted ? std::optional<Lens>(frame.camera) : std::nullopt;
  cv::Mat image = AnnotatePose(frame.gray, frame.lines, frame.pose, frame.camera, undistorted_by,
                               frame.tracked.region);
  DrawGoalLines(&image, frame.target, frame.cdMo, frame.camera);
  cv::putText(image, "dashed: at the goal", cv::Point(image.cols - 160, 16),
              cv::FONT_HERSHEY_SIMPLEX, 0.45, kBlack, 3, cv::LINE_AA);
  cv::putText(image, "dashed: at the goal", cv::Point(image.cols - 160, 16),
              cv::FONT_HERSHEY_SIMPLEX, 0.45, kWhite, 1, cv::LINE_AA);
  const ServoIteration& row = frame.row;
  std::string caption = "frame " + std::to_string(row.iteration) + "  " + row.status;
  if (std::isfinite(row.translation_error_mm)) {
    caption += "  error " + Fixed(row.translation_error_mm, 2) + " mm " +
               Fixed(row.rotation_error_deg, 3) + " deg";
  }
  const int y = image.rows - 10;
  cv::putText(image, caption, cv::Point(8, y), cv::FONT_HERSHEY_SIMPLEX, 0.5, kBlack, 3,
              cv::LINE_AA);
  cv::putText(image, caption, cv::Point(8, y), cv::FONT_HERSHEY_SIMPLEX, 0.5, kWhite, 1,
              cv::LINE_AA);
  return image;
}

void CheckWritableDirectory(const std::filesystem::path& dir, const std::string& what) {
  const std::string where = what + " '" + dir.string() + "'";
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) throw std::runtime_error("cannot create the " + where + ": " + error.message());
  if (!std::filesystem::is_directory(dir, error)) {
    throw std::runtime_error("the " + where + " is not a directory");
  }
  const std::filesystem::path probe = TempPathFor(dir / ".oalservo-write-check");
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) {
    throw std::runtime_error("cannot write into the " + where + ": " + std::strerror(errno));
  }
  ::close(fd);
  RemoveQuietly(probe);
}

}  // namespace oal
