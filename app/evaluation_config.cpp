#include "app/evaluation_config.h"

#include <yaml-cpp/yaml.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include "app/command_line.h"
#include "app/frame_command.h"  // CompanionFile
#include "base/check.h"
#include "io/atomic_file.h"
#include "io/camera_file.h"
#include "io/image_source.h"
#include "io/json_io.h"

namespace oal {
CLI::Option* AddSeedOption(CLI::App& cli, std::uint64_t* seed, const std::string& help) {
  const CLI::Validator non_negative(
      [](std::string& text) {
        const auto first = text.find_first_not_of(" \t");
        return first != std::string::npos && text[first] == '-'
                   ? "a seed is an integer >= 0, not " + text
                   : std::string();
      },
      "SEED >= 0", "non-negative seed");
  return cli.add_option("--seed", *seed, help)->capture_default_str()->check(non_negative);
}

void AddRenderedFrameOptions(CLI::App& cli, RenderedFrameOptions* options,
                             const std::string& kdu_help) {
  cli.add_option("--frames", options->frames, "number of rendered frames, [1, 1000000]")
      ->capture_default_str();
  cli.add_option("--first-frame", options->first_frame,
                 "start at this frame of the seed's sequence, [0, 1000000]: the frames before it "
                 "are drawn, not rendered, so one frame of a long run is replayed exactly as it "
                 "was (--first-frame 730 --frames 1)")
      ->capture_default_str();
  AddSeedOption(cli, &options->seed, "seed of poses and noise, >= 0");
  // The defaults depend on the target (ApplySheetDefaults): said in words, not shown.
  cli.add_option("--kdu", options->kdu,
                 kdu_help + ", -1 < kdu < 1 (default: 0.33; a sheet target 0.15)");
  cli.add_option("--noise", options->noise_sigma,
                 "noise sigma, grey levels, [0, 100] (default: 8; a sheet target 2, to "
                 "--noise-max 8)");
  cli.add_option("--blur", options->blur_sigma_px,
                 "blur sigma, pixels, [0, 20] (default: 1; a sheet target 0.5, to --blur-max "
                 "1.5)");
  cli.add_option("--noise-max", options->noise_max,
                 "each frame's noise uniform between --noise and this (default: --noise alone)");
  cli.add_option("--blur-max", options->blur_max_px,
                 "each frame's blur uniform between --blur and this (default: --blur alone)");
  cli.add_option("--background", options->backgrounds,
                 "image of the surface the target lies on; several are used in turn from frame "
                 "to frame (default: the config's scene.background, else a uniform grey, except "
                 "for the sheet targets: photographs of Debian's visp-images-data)");
}

std::vector<std::pair<std::string, std::string>> RenderedFrameOptionWords() {
  return {{"RenderedFrameOptions::frames", "--frames"},
          {"RenderedFrameOptions::first_frame", "--first-frame"},
          {"RenderedFrameOptions::kdu", "--kdu"},
          {"RenderedFrameOptions::noise_sigma", "--noise"},
          {"RenderedFrameOptions::blur_sigma_px", "--blur"},
          {"RenderedFrameOptions::noise_max", "--noise-max"},
          {"RenderedFrameOptions::blur_max_px", "--blur-max"},
          {"RenderedFrameOptions::illumination_gradient", "--gradient"},
          {"RenderedFrameOptions::focal_px", "--focal"},
          {"PoseSampling::min_distance_m", "--min-distance"},
          {"PoseSampling::max_distance_m", "--max-distance"},
          {"PoseSampling::max_tilt_deg", "--max-tilt-deg"},
          {"PoseSampling::max_offset_m", "--max-offset"}};
}

void AddRenderedCameraOptions(CLI::App& cli, RenderedFrameOptions* options,
                              std::string* camera_path) {
  cli.add_option("--width", options->width, "image width, pixels, [16, 8192]")
      ->capture_default_str();
  cli.add_option("--height", options->height, "image height, pixels, [16, 8192]")
      ->capture_default_str();
  cli.add_option("--focal", options->focal_px,
                 "focal length, pixels (default: 600 at 640 px wide, in proportion to --width: "
                 "56 deg across; a 70 deg webcam is 914 at 1280, 1371 at 1920)");
  cli.add_option("--camera", *camera_path,
                 "render through this camera file's lens (ViSP's .xml, OpenCV's or ROS's .yaml) "
                 "at its image size, instead of --focal and --kdu")
      ->check(CLI::ExistingFile);
}

void ApplyRenderedCameraOptions(const CLI::App& cli, const std::string& camera_path,
                                RenderedFrameOptions* options) {
  const auto given = [&cli](const char* name) {
    const CLI::Option* option = cli.get_option_no_throw(name);
    return option != nullptr && option->count() > 0;
  };
  if (camera_path.empty()) {
    if (given("--width") && !given("--focal")) options->focal_px = 600.0 * options->width / 640.0;
    return;
  }
  for (const char* name : {"--focal", "--kdu"}) {
    if (given(name)) {
      throw std::runtime_error(std::string(name) + " cannot be given with --camera " + camera_path +
                               ": the camera file gives it");
    }
  }
  const CameraFile file = LoadCameraFile(camera_path);
  options->camera = file.camera;
  if (file.width > 0 && file.height > 0) {
    if ((given("--width") && static_cast<unsigned>(options->width) != file.width) ||
        (given("--height") && static_cast<unsigned>(options->height) != file.height)) {
      throw std::runtime_error("--width/--height " + std::to_string(options->width) + "x" +
                               std::to_string(options->height) + " disagree with --camera " +
                               camera_path + ", calibrated at " + std::to_string(file.width) + "x" +
                               std::to_string(file.height));
    }
    options->width = static_cast<int>(file.width);
    options->height = static_cast<int>(file.height);
  }
}

AppConfig LoadAccuracyConfig(const std::string& path, const std::string& command,
                             const std::vector<std::string>& used, const std::string& note) {
  AppConfig config = LoadConfig(path);  // syntax, unknown sections and keys, values
  const YAML::Node root = YAML::LoadFile(path);
  if (!root.IsMap()) return config;  // an empty file
  std::string reads;
  for (const std::string& name : used) reads += (reads.empty() ? "" : ", ") + name;
  for (const auto& entry : root) {
    const std::string name = entry.first.Scalar();
    if (std::find(used.begin(), used.end(), name) != used.end()) continue;
    throw std::runtime_error(path + ":" + std::to_string(entry.first.Mark().line + 1) +
                             ": section '" + name + "' is not used by oalservo " + command +
                             " (it reads: " + reads + "); " + note);
  }
  return config;
}

bool ConfigHasSection(const std::string& path, const std::string& section) {
  const YAML::Node root = YAML::LoadFile(path);
  return root.IsMap() && root[section].IsDefined();
}

TrackerSetup TrackerSetupOf(const std::string& config_path,
                            const std::vector<std::string>& inputs) {
  AppConfig config;
  if (!config_path.empty()) config = LoadConfig(config_path, config);
  TrackerSetup setup;
  setup.detector = config.detector;
  setup.pose = config.pose;
  setup.tracking = config.tracking;
  if (!config_path.empty() && ConfigHasSection(config_path, "target")) {
    setup.target = config.target;
    setup.target_origin = config_path;
  } else if (const std::optional<std::string> companion = CompanionFile(inputs, "target.yaml")) {
    setup.target = LoadConfig(*companion).target;  // the target `oalservo render` drew
    setup.target_origin = *companion;
  }
  return setup;
}

LineTarget AccuracyTarget(const std::string& target_name, bool target_given,
                          const std::string& config_path, const AppConfig& config) {
  if (!config_path.empty() && ConfigHasSection(config_path, "target")) {
    if (target_given) {
      throw UsageError("--target " + target_name + " and the target: section of " + config_path +
                       ": give one of them");
    }
    return config.target;
  }
  try {
    return TargetByName(target_name);
  } catch (const std::invalid_argument& error) {
    throw std::invalid_argument(std::string("--target: ") + error.what());
  }
}

void ApplySheetDefaults(const CLI::App& cli, const LineTarget& target, bool scene_given,
                        RenderedFrameOptions* options, PoseSampling* sampling) {
  if (!IsSheet(target)) return;
  const auto given = [&cli](const char* name) {
    const CLI::Option* option = cli.get_option_no_throw(name);
    return option != nullptr && option->count() > 0;
  };
  PoseSampling sheet = SheetSampling(target);
  if (given("--min-distance")) sheet.min_distance_m = sampling->min_distance_m;
  if (given("--max-distance")) sheet.max_distance_m = sampling->max_distance_m;
  if (given("--max-tilt-deg")) sheet.max_tilt_deg = sampling->max_tilt_deg;
  if (given("--max-offset")) sheet.max_offset_m = sampling->max_offset_m;
  if (given("--crossings-margin")) sheet.crossings_margin_px = sampling->crossings_margin_px;
  if (given("--min-visible-px")) sheet.min_visible_length_px = sampling->min_visible_length_px;
  *sampling = sheet;
  if (!given("--kdu")) options->kdu = 0.15;
  if (!given("--noise")) options->noise_sigma = 2.0;
  if (!given("--noise-max")) options->noise_max = given("--noise") ? -1.0 : 8.0;
  if (!given("--blur")) options->blur_sigma_px = 0.5;
  if (!given("--blur-max")) options->blur_max_px = given("--blur") ? -1.0 : 1.5;
  if (!scene_given) options->scene = BenchScene();
  if (!given("--background") && options->scene.background.empty()) {
    options->backgrounds = DefaultBenchPhotos();
  }
}

void CheckReportFile(const std::string& out_path) {
  if (out_path.empty()) return;
  try {
    CheckOutputFile(out_path);
    const AtomicFile probe(out_path);  // creates the temporary file; its destructor removes it
  } catch (const std::exception& error) {
    throw std::runtime_error("cannot write --out '" + out_path + "': " + error.what());
  }
}

void PrintAccuracyReport(const std::string& table, const nlohmann::json& json,
                         const std::string& out_path) {
  if (!out_path.empty()) WriteFileAtomically(out_path, json.dump(2) + '\n');
  WriteText(std::cout, table);
}

}  // namespace oal
