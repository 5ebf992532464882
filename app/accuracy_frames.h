// What the accuracy evaluations over rendered frames (`oalservo detect-accuracy`,
// `oalservo pose-accuracy`) share: how the frames are rendered, and the command-line options,
// JSON and output of their reports.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "app/config.h"
#include "scene/scene.h"

namespace CLI {
class App;
class Option;
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

  /// Throws std::invalid_argument naming the command-line option and its range: --frames
  /// [1, 1000000], --kdu (-1, 1) (as `oalservo render`), --noise [0, 100], --blur [0, 20],
  /// --gradient [0, 0.9]; and width, height >= 16, focal_px > 0.
  void Check() const;
};

/// The renderer's options for `options`: a centred camera with focal_px and kdu, noise, blur.
RenderOptions MakeRenderOptions(const RenderedFrameOptions& options);

/// Adds --seed, described by `help`, with its default shown: an integer >= 0; a negative one
/// is a usage error (CLI11 alone would turn -1 into 2^64 - 1). For every command with a seed.
CLI::Option* AddSeedOption(CLI::App& cli, std::uint64_t* seed, const std::string& help);

/// Adds --frames, --seed (AddSeedOption), --kdu (described by `kdu_help`), --noise and --blur.
void AddRenderedFrameOptions(CLI::App& cli, RenderedFrameOptions* options,
                             const std::string& kdu_help);

/// `options` as JSON, the start of a report's "options" object (each command adds its own).
nlohmann::json RenderedFrameJson(const RenderedFrameOptions& options);

/// LoadConfig(path), and an error for any section of the file not in `used`: `command` would
/// silently ignore it (target:, camera:...), so it is rejected with
/// "FILE:LINE: section 'target' is not used by oalservo COMMAND (it reads: ...); NOTE".
AppConfig LoadAccuracyConfig(const std::string& path, const std::string& command,
                             const std::vector<std::string>& used, const std::string& note);

/// Checks before any work that the report file --out can be written: its folder exists and a
/// file can be created there (a temporary one, removed at once). Nothing when out_path is
/// empty. Throws std::runtime_error naming --out.
void CheckReportFile(const std::string& out_path);

/// Writes `json` (indented) atomically to out_path, if set; then prints `table` on stdout with
/// WriteText of app/json_io.h (a failed stdout is an error, reported after the file is safe).
void PrintAccuracyReport(const std::string& table, const nlohmann::json& json,
                         const std::string& out_path);

}  // namespace oal
