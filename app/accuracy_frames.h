// What the accuracy evaluations over rendered frames (`oalservo detect-accuracy`,
// `oalservo pose-accuracy`) share: how the frames are rendered, and the command-line options,
// JSON and output of their reports.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "scene/scene.h"

namespace CLI {
class App;
}  // namespace CLI

namespace oal {

/// The rendered frames of an accuracy evaluation: how many, their seed, camera and degradations.
struct RenderedFrameOptions {
  int frames = 1000;       ///< rendered frames, [1, 1000000]
  std::uint64_t seed = 1;  ///< poses and noise
  int width = 640, height = 480;
  double focal_px = 600.0;
  double kdu = 0.33;         ///< cheap wide lens (barrel, k1 ≈ -0.25)
  double noise_sigma = 8.0;  ///< grey levels
  double blur_sigma_px = 1.0;
  double illumination_gradient = 0.2;
};

/// The renderer's options for `options`: a centred camera with focal_px and kdu, noise, blur.
RenderOptions MakeRenderOptions(const RenderedFrameOptions& options);

/// Adds --frames, --seed, --kdu (described by `kdu_help`), --noise and --blur.
void AddRenderedFrameOptions(CLI::App& cli, RenderedFrameOptions* options,
                             const std::string& kdu_help);

/// `options` as JSON, the start of a report's "options" object (each command adds its own).
nlohmann::json RenderedFrameJson(const RenderedFrameOptions& options);

/// Prints `table` on stdout, then writes `json` (indented) atomically to out_path if set.
void PrintAccuracyReport(const std::string& table, const nlohmann::json& json,
                         const std::string& out_path);

}  // namespace oal
