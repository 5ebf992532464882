#include "app/detector_accuracy_command.h"

#include <CLI/CLI.hpp>
#include <cstdio>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/command_line.h"
#include "app/config.h"
#include "app/evaluation_config.h"
#include "base/statistics.h"
#include "eval/rendered/detector_accuracy.h"

namespace oal {
namespace {

std::string Table(const AccuracyReport& report) {
  std::ostringstream out;
  out << std::fixed;
  out << "| method | compared with | frames | failed | failure rate | angle err median / p95 (deg) "
         "| offset err median / p95 (px) | time median (us) |\n"
      << "|---|---|---:|---:|---:|---:|---:|---:|\n";
  for (const MethodAccuracy& m : report.methods) {
    out << "| " << m.name << " | " << m.reference << " | " << m.frames << " | " << m.failed_frames
        << " | " << std::setprecision(1) << 100.0 * m.FailureRate() << " % | "
        << std::setprecision(3) << Quantile(m.angle_error_deg, 0.5) << " / "
        << Quantile(m.angle_error_deg, 0.95) << " | " << Quantile(m.offset_error_px, 0.5) << " / "
        << Quantile(m.offset_error_px, 0.95) << " | " << std::setprecision(1)
        << Quantile(m.time_us, 0.5) << " |\n";
  }
  return out.str();
}

nlohmann::json ToJson(const AccuracyReport& report) {
  const AccuracyOptions& o = report.options;
  nlohmann::json json;
  json["options"] = RenderedFrameJson(o);
  json["options"]["target"] = o.target.name;
  json["options"]["max_angle_deg"] = o.max_angle_deg;
  json["options"]["max_offset_px"] = o.max_offset_px;
  json["options"]["min_visible_length_px"] = o.sampling.min_visible_length_px;
  for (const MethodAccuracy& m : report.methods) {
    json["methods"].push_back({{"name", m.name},
                               {"reference", m.reference},
                               {"frames", m.frames},
                               {"failed_frames", m.failed_frames},
                               {"failure_rate", m.FailureRate()},
                               {"angle_error_deg_median", Quantile(m.angle_error_deg, 0.5)},
                               {"angle_error_deg_p95", Quantile(m.angle_error_deg, 0.95)},
                               {"offset_error_px_median", Quantile(m.offset_error_px, 0.5)},
                               {"offset_error_px_p95", Quantile(m.offset_error_px, 0.95)},
                               {"time_us_median", Quantile(m.time_us, 0.5)},
                               {"failed_frame_indices", m.failed_frame_indices}});
  }
  return json;
}

}  // namespace

int RunDetectAccuracy(int argc, char** argv) {
  CLI::App cli{
      "Accuracy of the detector on rendered frames with ground truth (fixed seeds): our "
      "detector with and without point undistortion, the paper's algorithm, and OpenCV "
      "HoughLines on the same frames. A frame fails when any target line is missing from the "
      "first N lines or is off by more than --max-angle-deg or --max-offset-px (offset: the "
      "largest distance of the true visible chord's ends from the detected line).",
      "oalservo detect-accuracy"};
  AccuracyOptions options;
  std::string config_path, out_path, target_name = "four-line-board";
  CLI::Option* target = cli.add_option("--target", target_name,
                                       "a built-in target: " + TargetNameList() +
                                           " (a sheet: on photographs of a bench, as "
                                           "pose-accuracy)")
                            ->capture_default_str();
  AddRenderedFrameOptions(cli, &options, "lens distortion (ViSP kdu; 0.33 = cheap wide lens)");
  std::string camera_path;
  AddRenderedCameraOptions(cli, &options, &camera_path);
  cli.add_option("--gradient", options.illumination_gradient, "illumination fall-off, 0..0.9")
      ->capture_default_str();
  cli.add_option("--min-visible-px", options.sampling.min_visible_length_px,
                 "every target line crosses at least this much of the image")
      ->capture_default_str();
  cli.add_option("--max-tilt-deg", options.sampling.max_tilt_deg, "camera tilt bound")
      ->capture_default_str();
  cli.add_option("--max-angle-deg", options.max_angle_deg, "failure bound on angle")
      ->capture_default_str();
  cli.add_option("--max-offset-px", options.max_offset_px, "failure bound on offset")
      ->capture_default_str();
  cli.add_option("--max-offset", options.sampling.max_offset_m,
                 "the optical axis meets the target at most this far from its centre, metres");
  cli.add_option("--crossings-margin", options.sampling.crossings_margin_px,
                 "a sheet's four crossings at least this far inside the image, pixels");
  cli.add_option("--config", config_path,
                 "YAML config: its 'detector:', 'target:', 'tracking:' and 'scene:' sections "
                 "(another section is an error)")
      ->check(CLI::ExistingFile);
  cli.add_option("--out", out_path, "write the report as JSON to this file");
  cli.footer(
      "Examples:\n"
      "  oalservo detect-accuracy --frames 1000 --seed 1 --out out/detect-accuracy.json\n"
      "      the 2 m board through a cheap wide lens (the paper's condition)\n"
      "  oalservo detect-accuracy --target four-line-a3 --frames 1000 --seed 1\n"
      "      an A3 sheet on the bench photographs of Debian's visp-images-data");
  if (auto exit = ParseCommandLine(cli, argc, argv)) return *exit;
  ApplyRenderedCameraOptions(cli, camera_path, &options);

  // Everything that can fail before the evaluation's minutes of work.
  AppConfig config;
  if (!config_path.empty()) {
    config = LoadAccuracyConfig(
        config_path, "detect-accuracy", {"detector", "target", "tracking", "scene"},
        "it renders the target with the camera of its command-line options");
    options.detector = config.detector;
    options.tracking = config.tracking;
    options.scene = config.scene;
  }
  const bool scene_given = !config_path.empty() && ConfigHasSection(config_path, "scene");
  options.target = AccuracyTarget(target_name, target->count() > 0, config_path, config);
  ApplySheetDefaults(cli, options.target, scene_given, &options, &options.sampling);
  auto words = RenderedFrameOptionWords();
  words.insert(words.end(), {{"AccuracyOptions::max_angle_deg", "--max-angle-deg"},
                             {"AccuracyOptions::max_offset_px", "--max-offset-px"}});
  CheckInOptionWords([&] { options.Check(); }, words);
  CheckReportFile(out_path);
  const AccuracyReport report = EvaluateDetectorAccuracy(options, TerminalFrameProgress());
  PrintAccuracyReport(Table(report), ToJson(report), out_path);
  return kExitOk;
}

}  // namespace oal
