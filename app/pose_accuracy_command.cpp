#include "app/pose_accuracy_command.h"

#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "app/command_line.h"
#include "app/config.h"
#include "app/evaluation_config.h"
#include "base/format.h"
#include "base/statistics.h"
#include "eval/rendered/pose_accuracy.h"
#include "io/atomic_file.h"
#include "io/camera_file.h"
#include "io/json_io.h"
#include "io/rendered_dataset.h"
#include "io/truth_file.h"
#include "servo/pose.h"

namespace oal {
namespace {

// "1000", or "1 (from frame 730)" for a run that starts later in the seed's sequence.
std::string FramesCell(const PoseAccuracyReport& r) {
  const std::string count = std::to_string(r.frames);
  return r.options.first_frame > 0
             ? count + " (from frame " + std::to_string(r.options.first_frame) + ")"
             : count;
}

std::string Table(const PoseAccuracyReport& r) {
  std::ostringstream out;
  const auto count = [](const std::map<std::string, int>& counts, const std::string& key) {
    const auto found = counts.find(key);
    return found == counts.end() ? 0 : found->second;
  };
  const double frames = std::max(1, r.frames);
  out << std::fixed << std::setprecision(2) << "| measure | value |\n|---|---:|\n"
      << "| target | " << r.options.target.name << " |\n"
      << "| frames | " << FramesCell(r) << " |\n"
      << "| frames with a pose | " << r.posed() << " (" << 100.0 * r.posed() / frames << " %) |\n"
      << "| wrong poses (> " << r.options.wrong_translation_pct << " % or > "
      << r.options.wrong_rotation_deg << " deg) | " << r.wrong_frames.size() << " |\n";
  out << "| frames without a pose, by the tracker's status |";
  for (const TargetStatus status : {TargetStatus::kNotFound, TargetStatus::kModelMismatch}) {
    out << ' ' << ToString(status) << ' ' << count(r.status_counts, ToString(status))
        << (status == TargetStatus::kNotFound ? "," : "");
  }
  out << " |\n| ... by the last pose's status |";
  std::string pose_statuses;
  for (const auto& [status, n] : r.pose_status_counts) {
    pose_statuses += (pose_statuses.empty() ? " " : ", ") + status + " " + std::to_string(n);
  }
  out << (pose_statuses.empty() ? " none" : pose_statuses) << " |\n";
  out << "| all four lines within " << r.options.line_angle_deg << " deg / "
      << r.options.line_offset_px << " px | " << r.lines_found << " ("
      << 100.0 * r.lines_found / frames << " %) |\n";
  out << std::setprecision(3) << "| translation error median / p95 (% of distance) | "
      << Quantile(r.translation_error_pct, 0.5) << " / " << Quantile(r.translation_error_pct, 0.95)
      << " |\n"
      << "| rotation error median / p95 (deg) | " << Quantile(r.rotation_error_deg, 0.5) << " / "
      << Quantile(r.rotation_error_deg, 0.95) << " |\n"
      << "| roll error median / max (deg) | " << Quantile(r.roll_error_deg, 0.5) << " / "
      << Quantile(r.roll_error_deg, 1.0) << " |\n"
      << "| frames with roll off by > 45 deg | " << r.roll_flips << " |\n";
  if (r.options.estimate_distortion) {
    out << "| kdu told from the stripes of " << r.options.estimate_frames << " frames | "
        << (r.estimate_failed.empty()
                ? Fixed(r.estimated_kdu, 4) + " +- " + Fixed(r.estimated_kdu_sd, 4) + " (truth " +
                      Fixed(r.options.kdu, 4) + ")"
                : "none: " + r.estimate_failed + "; poses without distortion")
        << " |\n";
  }
  std::string sources;
  for (const auto& [source, n] : r.source_counts) {
    sources += (sources.empty() ? "" : ", ") + source + " " + std::to_string(n);
  }
  out << "| poses found by | " << sources << " |\n"
      << std::setprecision(1) << "| time median / p95 (us): find + detect + pose | "
      << Quantile(r.total_time_us, 0.5) << " / " << Quantile(r.total_time_us, 0.95) << " |\n"
      << "| — find / detect / pose medians (us) | " << Quantile(r.find_time_us, 0.5) << " / "
      << Quantile(r.detect_time_us, 0.5) << " / " << Quantile(r.pose_time_us, 0.5) << " |\n";
  return out.str();
}

// A marker's report: the rows of ours that a printed marker has (no lines, no scan sources),
// and how often all of it was in view.
std::string MarkerTable(const PoseAccuracyReport& r) {
  std::ostringstream out;
  const auto count = [&r](MarkerStatus status) {
    const auto found = r.status_counts.find(ToString(status));
    return found == r.status_counts.end() ? 0 : found->second;
  };
  const double frames = std::max(1, r.frames);
  out << std::fixed << std::setprecision(2) << "| measure | value |\n|---|---:|\n"
      << "| marker | " << ToString(r.options.marker) << ": " << r.marker_description << " |\n"
      << "| sheet | " << r.options.target.name << "'s board, without its stripes |\n"
      << "| frames | " << FramesCell(r) << " |\n"
      << "| frames with a pose | " << r.posed() << " (" << 100.0 * r.posed() / frames << " %) |\n"
      << "| wrong poses (> " << r.options.wrong_translation_pct << " % or > "
      << r.options.wrong_rotation_deg << " deg) | " << r.wrong_frames.size() << " |\n"
      << "| frames without a pose | " << ToString(MarkerStatus::kNotFound) << ' '
      << count(MarkerStatus::kNotFound) << ", " << ToString(MarkerStatus::kNoPose) << ' '
      << count(MarkerStatus::kNoPose) << " |\n"
      << "| frames with all of the marker in view / of them with a pose | " << r.marker_in_view
      << " (" << 100.0 * r.marker_in_view / frames << " %) / " << r.posed_in_view << " |\n";
  out << std::setprecision(3) << "| translation error median / p95 (% of distance) | "
      << Quantile(r.translation_error_pct, 0.5) << " / " << Quantile(r.translation_error_pct, 0.95)
      << " |\n"
      << "| rotation error median / p95 (deg) | " << Quantile(r.rotation_error_deg, 0.5) << " / "
      << Quantile(r.rotation_error_deg, 0.95) << " |\n"
      << "| roll error median / max (deg) | " << Quantile(r.roll_error_deg, 0.5) << " / "
      << Quantile(r.roll_error_deg, 1.0) << " |\n"
      << "| frames with roll off by > 45 deg | " << r.roll_flips << " |\n"
      << std::setprecision(1) << "| time median / p95 (us): detect + pose | "
      << Quantile(r.total_time_us, 0.5) << " / " << Quantile(r.total_time_us, 0.95) << " |\n"
      << "| — detect / pose medians (us) | " << Quantile(r.detect_time_us, 0.5) << " / "
      << Quantile(r.pose_time_us, 0.5) << " |\n";
  return out.str();
}

nlohmann::json ToJson(const PoseAccuracyReport& r, const std::string& config_path) {
  const PoseAccuracyOptions& o = r.options;
  nlohmann::json options = RenderedFrameJson(o);
  // The lens the pose was told, when it is not the rendered one (--pose-camera).
  if (o.given_camera) options["pose_camera"] = CameraJson(*o.given_camera, o.width, o.height);
  options["target"] = o.target.name;
  options["min_distance_m"] = o.sampling.min_distance_m;
  options["max_distance_m"] = o.sampling.max_distance_m;
  options["max_tilt_deg"] = o.sampling.max_tilt_deg;
  options["max_offset_m"] = o.sampling.max_offset_m;
  options["min_visible_length_px"] = o.sampling.min_visible_length_px;
  options["crossings_in_view"] = o.sampling.crossings_in_view;
  options["crossings_margin_px"] = o.sampling.crossings_margin_px;
  options["scan"] = ToString(o.tracking.scan);
  options["max_residual_px"] = o.pose.max_residual_px;
  if (!config_path.empty()) options["config"] = config_path;
  return {{"options", std::move(options)},
          {"frames", r.frames},
          {"posed", r.posed()},
          {"status_counts", r.status_counts},
          {"pose_status_counts", r.pose_status_counts},
          {"source_counts", r.source_counts},
          {"wrong_poses", r.wrong_frames},
          {"lines_found", r.lines_found},
          {"translation_error_pct_median", Quantile(r.translation_error_pct, 0.5)},
          {"translation_error_pct_p95", Quantile(r.translation_error_pct, 0.95)},
          {"rotation_error_deg_median", Quantile(r.rotation_error_deg, 0.5)},
          {"rotation_error_deg_p95", Quantile(r.rotation_error_deg, 0.95)},
          {"roll_error_deg_median", Quantile(r.roll_error_deg, 0.5)},
          {"roll_error_deg_max", Quantile(r.roll_error_deg, 1.0)},
          {"roll_flips", r.roll_flips},
          {"time_us_median", Quantile(r.total_time_us, 0.5)},
          {"find_time_us_median", Quantile(r.find_time_us, 0.5)},
          {"detect_time_us_median", Quantile(r.detect_time_us, 0.5)},
          {"pose_time_us_median", Quantile(r.pose_time_us, 0.5)},
          {"frames_without_pose", r.failed_frames},
          {"estimated_kdu", o.estimate_distortion && r.estimate_failed.empty()
                                ? nlohmann::json(r.estimated_kdu)
                                : nlohmann::json()}};
}

// A marker's report: ours' keys that a printed marker has, the marker, its time's p95 and how
// often all of it was in view.
nlohmann::json MarkerJson(const PoseAccuracyReport& r, const std::string& config_path) {
  nlohmann::json json = ToJson(r, config_path);
  for (const char* key : {"pose_status_counts", "source_counts", "lines_found",
                          "find_time_us_median", "estimated_kdu"}) {
    json.erase(key);
  }
  json["options"].erase("scan");
  json["options"].erase("max_residual_px");
  json["options"]["marker"] = ToString(r.options.marker);
  json["marker"] = r.marker_description;
  json["marker_in_view"] = r.marker_in_view;
  json["posed_in_view"] = r.posed_in_view;
  json["time_us_p95"] = Quantile(r.total_time_us, 0.95);
  return json;
}

// The evaluation conditions a target is made for, where the command line leaves them open:
// the paper's board as its first evaluation measured it; a sheet on photographs of a bench
// (ApplySheetDefaults).
void ApplyTargetDefaults(const CLI::App& cli, bool scene_given, PoseAccuracyOptions* options) {
  if (!IsSheet(options->target)) {
    if (cli.get_option("--min-distance")->count() == 0) {
      options->sampling = PoseAccuracyOptions::BoardSampling();
    }
    return;
  }
  ApplySheetDefaults(cli, options->target, scene_given, options, &options->sampling);
}

// A missed frame as `oalservo render` writes one (frame_NNNN.png and its truth), with what the
// tracker made of it under "pose_accuracy", so that `oalservo pose DIR` replays it.
void WriteMissedFrame(const std::filesystem::path& dir, const PoseAccuracyOptions& options,
                      const PoseAccuracyMiss& miss) {
  const RenderOptions& render = miss.render;
  Json truth = FrameTruthJson(miss.rendered, miss.frame, DatasetFrameName(miss.frame, ".png"),
                              options.target.name, options.seed, miss.noise_seed, render.camera,
                              render.width, render.height);
  truth["effects"] = EffectsJson(miss.effects);
  Json found{{"status", ToString(miss.result.status)},
             {"message", miss.result.message},
             {"source", ToString(miss.result.source)},
             {"wrong", miss.wrong}};
  if (miss.wrong) {
    found["translation_error_pct"] = miss.translation_error_pct;
    found["rotation_error_deg"] = miss.rotation_error_deg;
  }
  truth["pose_accuracy"] = std::move(found);
  WriteDatasetFrame(dir, miss.frame, miss.rendered, truth);
}

}  // namespace

int RunPoseAccuracy(int argc, char** argv) {
  CLI::App cli{
      "Accuracy of the camera pose from a four-line target on rendered frames (fixed seeds): "
      "each frame found on its own by the target tracker (the sheet's middle cell, borders on "
      "its plane, the model check), errors against the rendered pose. The conditions follow the "
      "target unless given: a sheet (default four-line-a3), printed with its annotations, lies "
      "on photographs of a bench among printed sheets and tools, with its shadow, under a cheap "
      "lens corrected by its camera file (kdu 0.15), noise 2-8 and blur 0.5-1.5 "
      "varying per frame, light fall-off, from the near to the far end of its range with its "
      "crossings in view; the 2 m board as the paper's condition (0.3-1.0 m, kdu 0.33, noise 8). "
      "--marker puts what users would print instead on the same frames: an AprilTag or a "
      "ChArUco board, each found and posed by its own library.",
      "oalservo pose-accuracy"};
  PoseAccuracyOptions options;
  std::string target_name = options.target.name, config_path, out_path;
  AddRenderedFrameOptions(cli, &options, "lens distortion (ViSP kdu)");
  std::string camera_path;
  AddRenderedCameraOptions(cli, &options, &camera_path);
  cli.add_option("--gradient", options.illumination_gradient,
                 "illumination fall-off across the image, [0, 0.9]")
      ->capture_default_str();
  CLI::Option* target =
      cli.add_option("--target", target_name, "a built-in target: " + TargetNameList())
          ->capture_default_str();
  cli.add_option("--min-distance", options.sampling.min_distance_m,
                 "metres (default: the target's)");
  cli.add_option("--max-distance", options.sampling.max_distance_m,
                 "metres (default: the target's)");
  cli.add_option("--max-tilt-deg", options.sampling.max_tilt_deg,
                 "camera tilt bound, degrees (default: the target's)");
  cli.add_option("--max-offset", options.sampling.max_offset_m,
                 "the optical axis meets the target at most this far from its centre, metres");
  cli.add_option("--crossings-margin", options.sampling.crossings_margin_px,
                 "a sheet's four crossings at least this far inside the image, pixels");
  cli.add_option("--config", config_path,
                 "YAML config: its 'target:', 'detector:', 'pose:', 'tracking:' and 'scene:' "
                 "sections; another section is an error")
      ->check(CLI::ExistingFile);
  cli.add_option("--out", out_path, "write the report as JSON to this file");
  std::string missed_dir;
  bool overwrite = false;
  cli.add_option("--save-missed", missed_dir,
                 "write each frame without a pose or with a wrong one into this folder as "
                 "`oalservo render` writes frames (frame_NNNN.png, its truth and what the tracker "
                 "said in frame_NNNN.json, camera.xml, target.yaml), to replay with `oalservo "
                 "pose DIR`; a folder that already holds a data set is refused unless "
                 "--overwrite");
  cli.add_flag("--overwrite", overwrite,
               "replace the data set already in --save-missed (its frame_NNNN.png/json, "
               "camera.xml and target.yaml; other files are kept)");
  cli.add_flag("--estimate-distortion", options.estimate_distortion,
               "do not tell the tracker the lens: estimate one radial term (ViSP's kdu, all four "
               "stripes can tell) from the target's stripes in frames of other poses, then use "
               "it");
  std::string given_camera_path;
  cli.add_option("--pose-camera", given_camera_path,
                 "the camera file the tracker (or the marker's method) poses with, e.g. a "
                 "calibration's result, instead of the rendered lens (--camera): what the "
                 "camera file costs")
      ->check(CLI::ExistingFile)
      ->excludes("--estimate-distortion");
  cli.add_option("--estimate-frames", options.estimate_frames,
                 "frames with the target that --estimate-distortion tells the lens from")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  std::string marker_name = ToString(SheetMarker::kOal);
  cli.add_option("--marker", marker_name,
                 "what the sheet carries, on the same frames (poses, bench, lived-in effects, "
                 "noise): oal (our '#' stripes, found by the target tracker), apriltag (an "
                 "AprilTag 36h11 found and posed by ViSP's detector) or charuco (a 10x7 ChArUco "
                 "board found and posed by OpenCV) printed on the target's sheet instead")
      ->capture_default_str();
  cli.footer(
      "Examples:\n"
      "  oalservo pose-accuracy --frames 1000 --seed 1 --out out/pose-a3.json\n"
      "  oalservo pose-accuracy --target four-line-a4 --frames 1000 --seed 2\n"
      "  oalservo pose-accuracy --target four-line-board --frames 1000 --seed 1\n"
      "  oalservo pose-accuracy --config config/scene-dark-table.yaml --frames 1000 --seed 3\n"
      "  oalservo pose-accuracy --frames 1000 --seed 4 --save-missed out/missed\n"
      "  oalservo pose-accuracy --frames 1000 --seed 1 --marker apriltag   # the same frames\n"
      "  oalservo pose out/missed   # the missed frames again, one JSON line each");
  if (auto exit = ParseCommandLine(cli, argc, argv)) return *exit;
  try {
    options.marker = SheetMarkerFromString(marker_name);
  } catch (const std::invalid_argument& error) {
    throw UsageError(std::string("--marker: ") + error.what());
  }
  if (options.marker != SheetMarker::kOal) {
    if (!missed_dir.empty()) {
      throw UsageError(
          "--save-missed keeps frames for `oalservo pose`, which runs our tracker: "
          "only with --marker oal");
    }
    if (options.estimate_distortion) {
      throw UsageError(
          "--estimate-distortion tells the lens from our target's stripes: only "
          "with --marker oal (a marker's method is given the rendered camera)");
    }
  }
  ApplyRenderedCameraOptions(cli, camera_path, &options);
  if (!given_camera_path.empty()) options.given_camera = LoadCameraFile(given_camera_path).camera;

  // Everything that can fail before the evaluation's minutes of work.
  AppConfig config;
  if (!config_path.empty()) {
    config = LoadAccuracyConfig(
        config_path, "pose-accuracy", {"target", "detector", "pose", "tracking", "scene"},
        "it renders the target with the camera of its command-line options");
    options.detector = config.detector;
    options.pose = config.pose;
    options.tracking = config.tracking;
    options.scene = config.scene;
  }
  const bool scene_given = !config_path.empty() && ConfigHasSection(config_path, "scene");
  options.target = AccuracyTarget(target_name, target->count() > 0, config_path, config);
  ApplyTargetDefaults(cli, scene_given, &options);
  CheckInOptionWords([&] { options.Check(); }, RenderedFrameOptionWords());
  CheckReportFile(out_path);
  std::optional<StagedDataset> missed;
  if (!missed_dir.empty())
    missed.emplace(missed_dir, overwrite, StagedDataset::Names{"--save-missed", "--overwrite"});
  std::optional<RenderOptions> render;  // of the first missed frame: the camera file's
  const PoseAccuracyReport report =
      EvaluatePoseAccuracy(options, TerminalFrameProgress(), [&](const PoseAccuracyMiss& miss) {
        if (!missed) return;
        WriteMissedFrame(missed->dir(), options, miss);
        if (!render) render = miss.render;
      });
  if (missed) {
    // Every frame has the same camera (none is written when no frame was missed).
    if (render) SaveDatasetCamera(missed->dir(), *render, "oal-pose-accuracy");
    WriteFileAtomically(missed->dir() / "target.yaml", TargetYaml(options.target));
    missed->Commit();
  }
  if (options.marker == SheetMarker::kOal) {
    PrintAccuracyReport(Table(report), ToJson(report, config_path), out_path);
  } else {
    PrintAccuracyReport(MarkerTable(report), MarkerJson(report, config_path), out_path);
  }
  if (missed) {
    const std::size_t missed_frames = report.failed_frames.size() + report.wrong_frames.size();
    std::cerr << "oalservo pose-accuracy: " << missed_frames
              << " frame(s) without a pose or with a wrong one written to " << missed_dir
              << (missed_frames > 0 ? " (replay: oalservo pose " + missed_dir + ")" : "") << "\n";
  }
  return kExitOk;
}

}  // namespace oal
