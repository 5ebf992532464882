#include "app/pose_accuracy_command.h"

#include <CLI/CLI.hpp>
#include <cstdio>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/accuracy_frames.h"
#include "app/command_line.h"
#include "app/config.h"
#include "app/detector_accuracy.h"  // Quantile
#include "app/pose_accuracy.h"
#include "servo/pose.h"

namespace oal {
namespace {

std::string Table(const PoseAccuracyReport& r) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(3);
  const double no_pose = 100.0 * (r.frames - r.posed()) / std::max(1, r.frames);
  out << "| measure | value |\n|---|---:|\n"
      << "| frames | " << r.frames << " |\n"
      << "| frames without a pose | " << r.frames - r.posed() << " (" << std::setprecision(2)
      << no_pose << " %) |\n";
  for (PoseStatus status :
       {PoseStatus::kNotEnoughLines, PoseStatus::kNotIdentifiable, PoseStatus::kDegenerate}) {
    out << "| — " << ToString(status) << " | " << r.status_counts[static_cast<std::size_t>(status)]
        << " |\n";
  }
  out << std::setprecision(3) << "| translation error median / p95 (% of distance) | "
      << Quantile(r.translation_error_pct, 0.5) << " / " << Quantile(r.translation_error_pct, 0.95)
      << " |\n"
      << "| rotation error median / p95 (deg) | " << Quantile(r.rotation_error_deg, 0.5) << " / "
      << Quantile(r.rotation_error_deg, 0.95) << " |\n"
      << "| roll error median / max (deg) | " << Quantile(r.roll_error_deg, 0.5) << " / "
      << Quantile(r.roll_error_deg, 1.0) << " |\n"
      << "| frames with roll off by > 45 deg | " << r.roll_flips << " |\n"
      << std::setprecision(1) << "| pose step median / p95 (us) | " << Quantile(r.pose_time_us, 0.5)
      << " / " << Quantile(r.pose_time_us, 0.95) << " |\n"
      << "| detector median (us) | " << Quantile(r.detect_time_us, 0.5) << " |\n";
  return out.str();
}

// {"ok": 20, "not-enough-lines": 0, ...}: the frames of each PoseStatus, by its name.
nlohmann::json StatusCountsJson(const PoseAccuracyReport& r) {
  nlohmann::json counts = nlohmann::json::object();
  for (PoseStatus status : {PoseStatus::kOk, PoseStatus::kNotEnoughLines,
                            PoseStatus::kNotIdentifiable, PoseStatus::kDegenerate}) {
    counts[ToString(status)] = r.status_counts[static_cast<std::size_t>(status)];
  }
  return counts;
}

nlohmann::json ToJson(const PoseAccuracyReport& r, const std::string& config_path) {
  const PoseAccuracyOptions& o = r.options;
  nlohmann::json options = RenderedFrameJson(o);
  options["min_distance_m"] = o.sampling.min_distance_m;
  options["max_distance_m"] = o.sampling.max_distance_m;
  options["max_tilt_deg"] = o.sampling.max_tilt_deg;
  options["min_visible_length_px"] = o.sampling.min_visible_length_px;
  options["max_residual_px"] = o.pose.max_residual_px;
  if (!config_path.empty()) options["config"] = config_path;
  return {{"options", std::move(options)},
          {"frames", r.frames},
          {"posed", r.posed()},
          {"status_counts", StatusCountsJson(r)},
          {"translation_error_pct_median", Quantile(r.translation_error_pct, 0.5)},
          {"translation_error_pct_p95", Quantile(r.translation_error_pct, 0.95)},
          {"rotation_error_deg_median", Quantile(r.rotation_error_deg, 0.5)},
          {"rotation_error_deg_p95", Quantile(r.rotation_error_deg, 0.95)},
          {"roll_error_deg_median", Quantile(r.roll_error_deg, 0.5)},
          {"roll_error_deg_max", Quantile(r.roll_error_deg, 1.0)},
          {"roll_flips", r.roll_flips},
          {"pose_time_us_median", Quantile(r.pose_time_us, 0.5)},
          {"detect_time_us_median", Quantile(r.detect_time_us, 0.5)},
          {"frames_without_pose", r.failed_frames}};
}

}  // namespace

int RunPoseAccuracy(int argc, char** argv) {
  CLI::App cli{
      "Accuracy of the camera pose from the four-line target on rendered frames (fixed "
      "seeds): the detector with point undistortion, then line identification, "
      "intersections and vpPose; errors against the rendered pose.",
      "oalservo pose-accuracy"};
  PoseAccuracyOptions options;
  std::string config_path, out_path;
  AddRenderedFrameOptions(cli, &options, "lens distortion (ViSP kdu)");
  cli.add_option("--min-distance", options.sampling.min_distance_m, "metres")
      ->capture_default_str();
  cli.add_option("--max-distance", options.sampling.max_distance_m, "metres")
      ->capture_default_str();
  cli.add_option("--max-tilt-deg", options.sampling.max_tilt_deg, "camera tilt bound")
      ->capture_default_str();
  cli.add_option("--config", config_path,
                 "YAML config: its 'detector:' and 'pose:' sections (config/detector.yaml, "
                 "config/pose.yaml); another section is an error")
      ->check(CLI::ExistingFile);
  cli.add_option("--out", out_path, "write the report as JSON to this file");
  if (auto exit = ParseCommandLine(cli, argc, argv)) return *exit;

  // Everything that can fail before the evaluation's minutes of work.
  if (!config_path.empty()) {
    const AppConfig config = LoadAccuracyConfig(
        config_path, "pose-accuracy", {"detector", "pose"},
        "it renders the built-in four-line target with the camera of its command-line options");
    options.detector = config.detector;
    options.pose = config.pose;
  }
  options.Check();
  CheckReportFile(out_path);
  const PoseAccuracyReport report = EvaluatePoseAccuracy(options, TerminalFrameProgress());
  PrintAccuracyReport(Table(report), ToJson(report, config_path), out_path);
  return kExitOk;
}

}  // namespace oal
