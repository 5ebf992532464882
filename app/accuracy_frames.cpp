#include "app/accuracy_frames.h"

#include <yaml-cpp/yaml.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include "app/atomic_file.h"
#include "app/json_io.h"
#include "detector/options.h"  // RequireOption

namespace oal {
namespace {}  // namespace

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
}

RenderOptions MakeRenderOptions(const RenderedFrameOptions& options) {
  RenderOptions render;
  render.width = options.width;
  render.height = options.height;
  render.camera =
      CameraWithKdu(options.focal_px, options.focal_px, 0.5 * (options.width - 1),
                    0.5 * (options.height - 1), options.kdu, options.width, options.height);
  render.noise_sigma = options.noise_sigma;
  render.blur_sigma_px = options.blur_sigma_px;
  render.illumination_gradient = options.illumination_gradient;
  return render;
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
  cli.add_option("--frames", options->frames, "number of rendered frames")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000000));
  AddSeedOption(cli, &options->seed, "seed of poses and noise, >= 0");
  cli.add_option("--kdu", options->kdu, kdu_help + ", -1 < kdu < 1")->capture_default_str();
  cli.add_option("--noise", options->noise_sigma, "noise sigma, grey levels, [0, 100]")
      ->capture_default_str();
  cli.add_option("--blur", options->blur_sigma_px, "blur sigma, pixels, [0, 20]")
      ->capture_default_str();
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
          {"illumination_gradient", options.illumination_gradient}};
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
