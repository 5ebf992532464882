#include "app/accuracy_frames.h"

#include <CLI/CLI.hpp>
#include <iostream>

#include "app/atomic_file.h"

namespace oal {

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

void AddRenderedFrameOptions(CLI::App& cli, RenderedFrameOptions* options,
                             const std::string& kdu_help) {
  cli.add_option("--frames", options->frames, "number of rendered frames")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000000));
  cli.add_option("--seed", options->seed, "seed of poses and noise")->capture_default_str();
  cli.add_option("--kdu", options->kdu, kdu_help)->capture_default_str();
  cli.add_option("--noise", options->noise_sigma, "noise sigma, grey levels")
      ->capture_default_str();
  cli.add_option("--blur", options->blur_sigma_px, "blur sigma, pixels")->capture_default_str();
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

void PrintAccuracyReport(const std::string& table, const nlohmann::json& json,
                         const std::string& out_path) {
  std::cout << table;
  if (!out_path.empty()) WriteFileAtomically(out_path, json.dump(2) + '\n');
}

}  // namespace oal
