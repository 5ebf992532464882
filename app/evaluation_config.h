// What the evaluation commands read from a configuration and their command line into eval/'s
// Options: the rendered frames' options and the sheet's evaluation conditions, the target, our
// detector's setup, and the output of their reports.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "app/config.h"
#include "eval/lines/oal_methods.h"
#include "eval/rendered/rendered_frames.h"
#include "scene/bench_scene.h"  // IsSheet, SheetSampling
#include "scene/scene.h"

namespace CLI {
class App;
class Option;
}  // namespace CLI

namespace oal {

/// Adds --seed, described by `help`, with its default shown: an integer >= 0; a negative one
/// is a usage error (CLI11 alone would turn -1 into 2^64 - 1). For every command with a seed.
CLI::Option* AddSeedOption(CLI::App& cli, std::uint64_t* seed, const std::string& help);

/// Adds --frames, --seed (AddSeedOption), --kdu (described by `kdu_help`), --noise and --blur.
void AddRenderedFrameOptions(CLI::App& cli, RenderedFrameOptions* options,
                             const std::string& kdu_help);

/// The fields of RenderedFrameOptions (and the PoseSampling it holds) as the options
/// AddRenderedFrameOptions, AddRenderedCameraOptions and the accuracy commands name them, for
/// CheckInOptionWords.
std::vector<std::pair<std::string, std::string>> RenderedFrameOptionWords();

/// Adds the rendered camera's options: --width, --height, --focal, and --camera FILE (a ViSP
/// camera file, whose camera and image size replace them and --kdu).
void AddRenderedCameraOptions(CLI::App& cli, RenderedFrameOptions* options,
                              std::string* camera_path);

/// After parsing: the camera file `camera_path` (when given) read into options->camera and its
/// image size into width and height (when it has one); with --width and no --focal, the
/// focal length that keeps the reference camera's field of view (600 px at 640 px wide).
/// Throws std::runtime_error naming --camera, or naming the options that cannot go with it.
void ApplyRenderedCameraOptions(const CLI::App& cli, const std::string& camera_path,
                                RenderedFrameOptions* options);

/// Whether the YAML file at `path` (read before, without error) has a top-level `section`.
bool ConfigHasSection(const std::string& path, const std::string& section);

/// The target of an accuracy command: the config's `target:` section when it has one (and
/// `target_given` is false: both is an error naming them), else the built-in `target_name`
/// (an unknown one is an error naming --target). `config_path` may be empty (no config).
LineTarget AccuracyTarget(const std::string& target_name, bool target_given,
                          const std::string& config_path, const AppConfig& config);

/// The conditions a sheet target is evaluated in, where the command line (`cli`, after
/// parsing) leaves them open: SheetSampling (but for --min-distance, --max-distance,
/// --max-tilt-deg, --max-offset, --crossings-margin given), a cheap lens corrected with its
/// camera file (kdu 0.15), noise 2-8 and blur 0.5-1.5 px drawn per frame, BenchScene()
/// unless `scene_given` (a config's scene:), on DefaultBenchPhotos() unless a background is
/// given. Nothing for the board.
void ApplySheetDefaults(const CLI::App& cli, const LineTarget& target, bool scene_given,
                        RenderedFrameOptions* options, PoseSampling* sampling);

/// Our detector, pose and tracking from the configuration at `config_path` (""; defaults), and
/// the target the frames of `inputs` show: the configuration's target: section, else the
/// target.yaml `oalservo render` wrote beside them (CompanionFile), else none. Throws
/// std::runtime_error "FILE:LINE: ..." for a malformed file.
TrackerSetup TrackerSetupOf(const std::string& config_path, const std::vector<std::string>& inputs);

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
/// WriteText of io/json_io.h (a failed stdout is an error, reported after the file is safe).
void PrintAccuracyReport(const std::string& table, const nlohmann::json& json,
                         const std::string& out_path);

}  // namespace oal
