#include "app/accuracy_frames.h"

#include <yaml-cpp/yaml.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include "app/command_line.h"
#include "base/check.h"
#include "io/atomic_file.h"
#include "io/image_source.h"
#include "io/json_io.h"

namespace oal {
namespace {

constexpr const char* kVispImages = "/usr/share/visp-images-data/ViSP-images";

}  // namespace

double Uniform01(std::uint64_t seed, int frame, std::uint64_t stream) {
  std::uint64_t x = seed * 0x9E3779B97F4A7C15ULL +
                    static_cast<std::uint64_t>(frame) * 0xBF58476D1CE4E5B9ULL + stream;
  x ^= x >> 30;
  x *= 0xBF58476D1CE4E5B9ULL;
  x ^= x >> 27;
  x *= 0x94D049BB133111EBULL;
  x ^= x >> 31;
  return static_cast<double>(x >> 11) * 0x1.0p-53;
}

void RenderedFrameOptions::Check() const {
  RequireOption(frames >= 1 && frames <= 1000000, "--frames", frames, "1 <= --frames <= 1000000");
  RequireOption(kdu > -1.0 && kdu < 1.0, "--kdu", kdu, "-1 < --kdu < 1");
  RequireOption(noise_sigma >= 0.0 && noise_sigma <= 100.0, "--noise", noise_sigma,
                "0 <= --noise <= 100");
  RequireOption(blur_sigma_px >= 0.0 && blur_sigma_px <= 20.0, "--blur", blur_sigma_px,
                "0 <= --blur <= 20");
  RequireOption(illumination_gradient >= 0.0 && illumination_gradient <= 0.9, "--gradient",
                illumination_gradient, "0 <= --gradient <= 0.9");
  RequireOption(width >= 16 && height >= 16, "RenderedFrameOptions::width, height",
                std::to_string(width) + "x" + std::to_string(height), "both >= 16");
  RequireOption(focal_px > 0.0 && std::isfinite(focal_px), "RenderedFrameOptions::focal_px",
                focal_px, "focal_px > 0");
  RequireOption(noise_max <= 100.0, "--noise-max", noise_max, "--noise-max <= 100");
  RequireOption(blur_max_px <= 20.0, "--blur-max", blur_max_px, "--blur-max <= 20");
}

RenderOptions MakeRenderOptions(const RenderedFrameOptions& options) {
  RenderOptions render;
  render.width = options.width;
  render.height = options.height;
  render.camera =
      CameraWithKdu(options.focal_px, options.focal_px, 0.5 * (options.width - 1),
                    0.5 * (options.height - 1), options.kdu, options.width, options.height);
  if (options.camera) render.camera = *options.camera;
  SceneConfig scene = options.scene;
  scene.background.clear();  // EvaluationScenes reads them
  scene.ApplyTo(&render);
  render.noise_sigma = options.noise_sigma;
  render.blur_sigma_px = options.blur_sigma_px;
  if (options.illumination_gradient > 0.0)
    render.illumination_gradient = options.illumination_gradient;
  return render;
}

EvaluationScenes::EvaluationScenes(const LineTarget& target, const RenderedFrameOptions& options)
    : options_(options) {
  std::vector<std::string> paths = options.backgrounds;
  if (paths.empty() && !options.scene.background.empty()) paths = {options.scene.background};
  const RenderOptions base = MakeRenderOptions(options);
  if (paths.empty()) {
    renderers_.emplace_back(target, base);
    names_.push_back("uniform grey");
    return;
  }
  for (const std::string& path : paths) {
    RenderOptions render = base;
    // Each bench its own clutter layout and paper texture.
    render.scene_seed = base.scene_seed + renderers_.size();
    try {
      render.background = options.scene.Surface(ReadGrayImage(path));
    } catch (const std::runtime_error& error) {
      throw std::runtime_error("background '" + path + "': " + error.what());
    }
    renderers_.emplace_back(target, render);
    names_.push_back(std::filesystem::path(path).filename().string());
  }
}

const SceneRenderer& EvaluationScenes::For(int frame) const {
  return renderers_[static_cast<std::size_t>(frame) % renderers_.size()];
}

std::string EvaluationScenes::BackgroundName(int frame) const {
  return names_[static_cast<std::size_t>(frame) % names_.size()];
}

FrameEffects EvaluationScenes::EffectsFor(int frame) const {
  FrameEffects effects;
  auto draw = [&](double lo, double hi, std::uint64_t stream) {
    return hi > lo ? lo + (hi - lo) * Uniform01(options_.seed, frame, stream) : lo;
  };
  effects.noise_sigma = draw(options_.noise_sigma, options_.noise_max, 1);
  effects.blur_sigma_px = draw(options_.blur_sigma_px, options_.blur_max_px, 2);
  return effects;
}

std::vector<std::string> DefaultBenchPhotos() {
  const std::vector<std::string> names = {
      "Klimt/Klimt.pgm",
      "AprilTag/AprilTag.pgm",
      "Solvay/Solvay_conference_1927_Version2_1024x705.png",
      "mire-2/image.0001.pgm",
      "mbt-depth/Castle-simu/Images/Image_0001.pgm",
      "mire/mire.pgm",
      "cube/image.0000.pgm",
  };
  std::vector<std::string> paths;
  for (const std::string& name : names) {
    const std::string path = std::string(kVispImages) + "/" + name;
    if (!std::filesystem::is_regular_file(path)) {
      throw std::runtime_error(
          "the default bench photographs come from Debian's visp-images-data (" + path +
          " is missing): install it (scripts/install-deps.sh) or give "
          "--background FILE");
    }
    paths.push_back(path);
  }
  return paths;
}

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

nlohmann::json RenderedFrameJson(const RenderedFrameOptions& options) {
  return {{"frames", options.frames},
          {"seed", options.seed},
          {"width", options.width},
          {"height", options.height},
          {"focal_px", options.focal_px},
          {"kdu", options.kdu},
          {"noise_sigma", options.noise_sigma},
          {"blur_sigma_px", options.blur_sigma_px},
          {"noise_max", options.noise_max},
          {"blur_max_px", options.blur_max_px},
          {"illumination_gradient", options.illumination_gradient},
          {"backgrounds", options.backgrounds}};
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

// scene/bench_scene.h's DressAsBench() as a config (the benchmarks and tests render it so).
SceneConfig BenchScene() {
  SceneConfig scene;
  scene.vignetting = 0.3;
  scene.shadow_darkness = 0.3;
  scene.paper_texture_grey = 3.0;
  scene.annotations = true;
  scene.clutter_sheets = 2;
  scene.clutter_objects = 4;
  scene.clutter_reach_m = 0.25;
  return scene;
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
