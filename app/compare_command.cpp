#include "app/compare_command.h"

#include <CLI/CLI.hpp>
#include <iostream>
#include <optional>

#include "app/command_line.h"
#include "app/evaluation_config.h"
#include "eval/lines/compare.h"
#include "io/json_io.h"
#include "io/quiet_stderr.h"

namespace oal {

int RunCompare(int argc, char** argv) {
  CompareOptions options;
  std::string target_kind = "auto";
  std::string config_path;
  bool verbose = false;
  CLI::App cli(
      "Run our OAL detector, ViSP's vpMeLine and OpenCV's line detectors on the same frames "
      "and compare them against ground truth: frames where every line was found, angle and "
      "offset errors, spurious lines, time per frame and per line. Prints a markdown table.",
      "oalservo compare");
  cli.add_option("INPUT", options.input,
                 "directory of images, printf pattern (frames/img%04d.png) or video")
      ->required();
  cli.add_option("--truth", options.truth,
                 "truth: a directory of frame_NNNN.json files, or a CSV with rows "
                 "frame,line,rho,theta (default: the .json next to each image)");
  cli.add_option("--config", config_path, "YAML configuration of our detector")
      ->check(CLI::ExistingFile);
  cli.add_option("--camera", options.camera_path,
                 "camera file (ViSP's .xml, OpenCV's or ROS's .yaml): our detector undistorts its "
                 "points and is scored against the truth's ideal lines");
  cli.add_option("--out", options.out_dir,
                 "directory for compare.md, compare.json and compare_frame_NNNN.png (created)");
  cli.add_option("--lines", options.lines,
                 "lines scored per frame and method (0: truth lines + 2); without truth, the "
                 "number of lines vpMeLine tracks (0: 4)")
      ->capture_default_str();
  cli.add_option("--max-frames", options.max_frames, "stop after N frames (0: all)");
  cli.add_option("--target", target_kind,
                 "stripes (centre lines; edge methods are paired), edges, or auto (edges when "
                 "the detector's polarity is edges)")
      ->capture_default_str();
  cli.add_option("--figures", options.figures, "figures written with --out (first, middle, worst)")
      ->capture_default_str();
  cli.add_option("--me-range", options.me.range_px, "vpMeLine search range, pixels")
      ->capture_default_str();
  cli.add_option("--me-threshold", options.me.threshold, "vpMeLine likelihood threshold")
      ->capture_default_str();
  cli.add_option("--me-step", options.me.sample_step_px, "vpMeLine sample step, pixels")
      ->capture_default_str();
  cli.add_flag("--verbose", verbose, "keep ViSP's own messages on stderr");
  cli.footer(
      "Examples:\n"
      "  oalservo render --count 30 --noise 4 --blur 1 --out data/\n"
      "  oalservo compare data/ --out out/compare\n"
      "  oalservo compare '/usr/share/visp-images-data/ViSP-images/line/image.%04d.pgm' "
      "--config config/visp_line_edges.yaml --truth line_reference.csv");
  if (const auto exit = ParseCommandLine(cli, argc, argv)) return *exit;
  options.target_kind = TargetKindFromString(target_kind);
  CheckInOptionWords([&] { options.Check(); }, {{"CompareOptions::lines", "--lines"},
                                                {"CompareOptions::max_frames", "--max-frames"},
                                                {"CompareOptions::figures", "--figures"},
                                                {"VpMeLineOptions::range_px", "--me-range"},
                                                {"VpMeLineOptions::threshold", "--me-threshold"},
                                                {"VpMeLineOptions::sample_step_px", "--me-step"}});
  options.setup = TrackerSetupOf(config_path, {options.input});
  options.names = {{"camera_path", "--camera"}, {"truth", "--truth"}};
  CompareReport report;
  {
    std::optional<QuietStderr> quiet;
    if (!verbose) quiet.emplace();
    report = RunComparison(options);
  }
  for (const std::string& warning : report.warnings) Warn("compare", warning);
  WriteText(std::cout, CompareMarkdown(report));
  if (!options.out_dir.empty()) {
    std::cerr << "oalservo compare: " << report.frames << " frames; table, JSON and "
              << report.figures.size() << " figures written to " << options.out_dir << '\n';
  }
  return kExitOk;
}

}  // namespace oal
