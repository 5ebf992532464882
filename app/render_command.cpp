#include "app/render_command.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/command_line.h"
#include "app/config.h"
#include "app/evaluation_config.h"  // AddSeedOption
#include "base/check.h"
#include "detector/lens.h"
#include "io/atomic_file.h"
#include "io/camera_file.h"
#include "io/rendered_dataset.h"
#include "scene/scene.h"
#include "scene/sequence.h"

namespace oal {
namespace {

namespace fs = std::filesystem;

constexpr const char* kCameraName = "oal-render";

// The render of the options: the config's scene (if any), then the command line's camera,
// noise, blur and light; --background replaces the scene's surface.
RenderOptions ToRenderOptions(const RenderCommandOptions& options, const SceneOptions& scene) {
  RenderOptions render;
  SceneOptions surface = scene;
  if (!options.background_image.empty()) {
    surface.background = options.background_image;
    surface.background_origin = "--background";
  }
  surface.ApplyTo(&render);
  render.width = options.width;
  render.height = options.height;
  render.camera = RenderCamera(options.width, options.height, options.fx_px, options.kdu);
  if (!options.camera_path.empty()) {
    const CameraFile file = LoadCameraFile(options.camera_path);
    render.camera = file.camera;
    if (file.width > 0 && file.height > 0) {
      render.width = static_cast<int>(file.width);
      render.height = static_cast<int>(file.height);
    }
  }
  render.noise_sigma = options.noise_sigma;
  render.blur_sigma_px = options.blur_sigma_px;
  if (options.gradient > 0.0) render.illumination_gradient = options.gradient;
  return render;
}

PoseSampling ToPoseSampling(const RenderCommandOptions& options) {
  PoseSampling sampling;
  sampling.min_distance_m = options.min_distance_m;
  sampling.max_distance_m = options.max_distance_m;
  sampling.max_tilt_deg = options.max_tilt_deg;
  sampling.min_tilt_deg = options.min_tilt_deg;
  sampling.max_offset_m = options.max_offset_m;
  sampling.min_visible_length_px = options.min_visible_px;
  sampling.crossings_in_view = options.crossings_margin_px >= 0.0;
  sampling.crossings_margin_px = std::max(0.0, options.crossings_margin_px);
  return sampling;
}

// The target and scene to render: the config's `target:` and `scene:` sections if a config
// is given, else the target by name on a plain surface.
AppConfig ConfigOf(const RenderCommandOptions& options) {
  if (!options.config.empty()) return LoadConfig(options.config);
  AppConfig config;
  config.target = TargetByName(options.target);
  return config;
}

// A sequence's render: its camera, noise, blur and light, on the config's scene (surface,
// fall-off, shadow, marks, clutter) or --background; the scene's gradient, when it sets one,
// replaces the sequence's.
RenderOptions SequenceRenderOptions(const RenderCommandOptions& options, const Sequence& sequence,
                                    const SceneOptions& scene) {
  RenderOptions render = sequence.options;
  SceneOptions surface = scene;
  if (!options.background_image.empty()) {
    surface.background = options.background_image;
    surface.background_origin = "--background";
  }
  surface.ApplyTo(&render);
  if (scene.gradient == 0.0) {
    render.illumination_gradient = sequence.options.illumination_gradient;
    render.gradient_angle_rad = sequence.options.gradient_angle_rad;
  }
  return render;
}

// Renders the sequence's frames, camera.xml and sequence.json into `dir`.
void RenderSequenceDataset(const RenderCommandOptions& options, const AppConfig& config,
                           const fs::path& dir) {
  const Sequence sequence = MakeSequence(SequenceKindFromString(options.sequence), options.count,
                                         options.seed, config.target);
  const SceneRenderer renderer(sequence.target,
                               SequenceRenderOptions(options, sequence, config.scene));
  WriteSequenceDataset(sequence, options.sequence, renderer,
                       DatasetLabels{config.target.name, options.seed, kCameraName}, dir);
}

// Renders independent random poses, their truth and camera.xml into `dir`.
void RenderRandomDataset(const RenderCommandOptions& options, const AppConfig& config,
                         const fs::path& dir) {
  const SceneRenderer renderer(config.target, ToRenderOptions(options, config.scene));
  WriteRandomDataset(renderer, ToPoseSampling(options), options.count,
                     DatasetLabels{config.target.name, options.seed, kCameraName}, dir,
                     config.scene.lived_in);
}

}  // namespace

void RenderCommandOptions::Check() const {
  if (!sequence.empty()) {
    try {
      SequenceKindFromString(sequence);
    } catch (const std::invalid_argument&) {
      RequireOption(false, "--sequence", sequence,
                    ("it is one of: " + SequenceKindNames()).c_str());
    }
  }
  if (config.empty()) {
    const std::vector<std::string>& names = TargetNames();
    RequireOption(
        target == "four-line" || std::find(names.begin(), names.end(), target) != names.end(),
        "--target", target, "it is one of " + TargetNameList());
  }
  RequireOption(count >= 1 && count <= 100000, "--count", count, "1 <= --count <= 100000");
  if (out_dir.empty()) throw std::invalid_argument("no output folder given (--out DIR)");
  RequireOption(width >= 16 && width <= 8192, "--width", width, "16 <= --width <= 8192");
  RequireOption(height >= 16 && height <= 8192, "--height", height, "16 <= --height <= 8192");
  RequireOption(fx_px > 0.0 && fx_px <= 1e5, "--fx", fx_px, "0 < --fx <= 100000");
  RequireOption(kdu > -1.0 && kdu < 1.0, "--kdu", kdu, "-1 < --kdu < 1");
  RequireOption(noise_sigma >= 0.0 && noise_sigma <= 100.0, "--noise", noise_sigma,
                "0 <= --noise <= 100");
  RequireOption(blur_sigma_px >= 0.0 && blur_sigma_px <= 20.0, "--blur", blur_sigma_px,
                "0 <= --blur <= 20");
  RequireOption(gradient >= 0.0 && gradient <= 0.9, "--gradient", gradient,
                "0 <= --gradient <= 0.9");
  RequireOption(min_distance_m > 0.0, "--min-distance", min_distance_m, "--min-distance > 0");
  RequireOption(max_distance_m >= min_distance_m, "--max-distance", max_distance_m,
                "--max-distance >= --min-distance");
  RequireOption(max_tilt_deg >= 0.0 && max_tilt_deg <= 80.0, "--max-tilt-deg", max_tilt_deg,
                "0 <= --max-tilt-deg <= 80");
  RequireOption(min_tilt_deg >= 0.0 && min_tilt_deg <= max_tilt_deg, "--min-tilt-deg", min_tilt_deg,
                "0 <= --min-tilt-deg <= --max-tilt-deg");
  RequireOption(min_visible_px >= 0.0, "--min-visible-px", min_visible_px, "--min-visible-px >= 0");
  RequireOption(max_offset_m >= 0.0 && max_offset_m <= 100.0, "--max-offset", max_offset_m,
                "0 <= --max-offset <= 100");
  RequireOption(crossings_margin_px >= -1.0 && crossings_margin_px <= 1000.0, "--crossings-margin",
                crossings_margin_px, "-1 <= --crossings-margin <= 1000");
  if (!background_image.empty() && !fs::is_regular_file(background_image)) {
    throw std::invalid_argument("--background image '" + background_image + "' does not exist");
  }
}

Lens RenderCamera(int width, int height, double fx_px, double kdu) {
  return Lens::WithKdu(fx_px, fx_px, 0.5 * (width - 1), 0.5 * (height - 1), kdu, width, height);
}

int RenderDataset(const RenderCommandOptions& options) {
  options.Check();
  const AppConfig config = ConfigOf(options);
  StagedDataset staged(options.out_dir, options.overwrite, {"--out", "--overwrite"});
  if (options.sequence.empty()) {
    RenderRandomDataset(options, config, staged.dir());
  } else {
    RenderSequenceDataset(options, config, staged.dir());
  }
  WriteFileAtomically(staged.dir() / "target.yaml", TargetYaml(config.target));
  staged.Commit();
  return options.count;
}

int RunRender(int argc, char** argv) {
  RenderCommandOptions options;
  CLI::App cli(
      "Render a synthetic data set of a line target with ground truth: DIR/frame_NNNN.png, "
      "DIR/frame_NNNN.json, DIR/camera.xml and DIR/target.yaml.",
      "oalservo render");
  CLI::Option* sequence = cli.add_option(
      "--sequence", options.sequence,
      "render a reproducible sequence instead of random poses: " + SequenceKindNames() +
          " (sets size, camera, noise, blur and poses)");
  CLI::Option* target = cli.add_option("--target", options.target,
                                       "a built-in target: " + TargetNameList() +
                                           " (four-line is an older name of four-line-board)")
                            ->capture_default_str();
  cli.add_option("--config", options.config,
                 "YAML file whose 'target:' section gives the target (instead of --target) and "
                 "whose 'scene:' section the surface, light, shadow and clutter")
      ->excludes(target)
      ->check(CLI::ExistingFile);
  CLI::Option* count = cli.add_option("--count", options.count,
                                      "number of frames (default with --sequence: " +
                                          std::to_string(kDefaultSequenceFrames) + ")")
                           ->capture_default_str();
  AddSeedOption(cli, &options.seed, "seed of the poses and the noise, >= 0");
  cli.add_option("--out", options.out_dir,
                 "output folder (created if missing); a folder that already holds a data set "
                 "is refused unless --overwrite")
      ->required();
  cli.add_flag("--overwrite", options.overwrite,
               "replace the data set already in --out: its frame_NNNN.png/json, camera.xml and "
               "sequence.json are removed; other files in the folder are kept");
  cli.add_option("--background", options.background_image,
                 "image of the surface the board lies on (replaces the config's "
                 "scene.background)");
  // Options that a sequence sets itself.
  const std::vector<CLI::Option*> random_pose_options = {
      cli.add_option("--width", options.width, "image width, pixels")->capture_default_str(),
      cli.add_option("--height", options.height, "image height, pixels")->capture_default_str(),
      cli.add_option("--fx", options.fx_px,
                     "focal length, pixels (fy = fx; principal point at the centre)")
          ->capture_default_str(),
      cli.add_option("--kdu", options.kdu, "lens distortion (ViSP kdu; 0.33 is a cheap wide lens)")
          ->capture_default_str(),
      cli.add_option(
             "--camera", options.camera_path,
             "render through this camera file's lens (ViSP's .xml, OpenCV's or ROS's .yaml) "
             "at its image size, instead of --fx, --kdu (and --width, --height when it "
             "has one)")
          ->check(CLI::ExistingFile),
      cli.add_option("--noise", options.noise_sigma, "Gaussian noise sigma, grey levels")
          ->capture_default_str(),
      cli.add_option("--blur", options.blur_sigma_px, "Gaussian blur sigma, pixels")
          ->capture_default_str(),
      cli.add_option("--gradient", options.gradient,
                     "illumination fall-off across the image, [0, 0.9]")
          ->capture_default_str(),
      cli.add_option("--max-offset", options.max_offset_m,
                     "where the optical axis meets the board, at most this far from its centre, "
                     "metres (larger: the board often partly out of view)")
          ->capture_default_str(),
      cli.add_option("--crossings-margin", options.crossings_margin_px,
                     "a '#' target's four crossings at least this far inside the image, pixels; "
                     "-1: not required")
          ->capture_default_str(),
      cli.add_option("--min-distance", options.min_distance_m, "camera to board, metres")
          ->capture_default_str(),
      cli.add_option("--max-distance", options.max_distance_m, "camera to board, metres")
          ->capture_default_str(),
      cli.add_option("--max-tilt-deg", options.max_tilt_deg,
                     "optical axis to board normal, degrees")
          ->capture_default_str(),
      cli.add_option("--min-tilt-deg", options.min_tilt_deg,
                     "... at least, degrees (views for a calibration: 30, with --max-tilt-deg 45)")
          ->capture_default_str(),
      cli.add_option("--min-visible-px", options.min_visible_px,
                     "every target line visible over at least this length, pixels")
          ->capture_default_str()};
  for (CLI::Option* option : random_pose_options) sequence->excludes(option);
  // The camera file gives the focal length and the lens.
  cli.get_option("--camera")->excludes(cli.get_option("--fx"))->excludes(cli.get_option("--kdu"));
  cli.footer(
      "All or nothing: the frames are rendered into a temporary folder next to --out "
      "(DIR.tmp-PID) and moved into --out only when all are written; on an error nothing is "
      "left behind, and a data set already in --out is untouched.\n\n"
      "Examples:\n  oalservo render --count 20 --kdu 0.33 --noise 4 --out data/\n"
      "  oalservo render --target four-line-a3 --min-distance 0.3 --max-distance 0.85 "
      "--count 20 --out a3/\n"
      "  oalservo detect data/ --camera data/camera.xml --out data/lines.jsonl\n"
      "  oalservo render --sequence fast --count 60 --seed 1 --out fast/\n"
      "  oalservo render --count 5 --out data/ --overwrite   # replaces the 20 frames above");
  if (const auto exit = ParseCommandLine(cli, argc, argv)) return *exit;
  if (!options.sequence.empty() && count->count() == 0) options.count = kDefaultSequenceFrames;
  const int frames = RenderDataset(options);
  std::cerr << "oalservo render: " << frames << " frames"
            << (options.sequence.empty() ? "" : " of sequence '" + options.sequence + "'")
            << " written to " << options.out_dir << '\n';
  return kExitOk;
}

}  // namespace oal
