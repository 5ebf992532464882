#include "app/render_command.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "app/command_line.h"
#include "app/config.h"
#include "app/evaluation_config.h"  // AddSeedOption
#include "base/check.h"
#include "io/atomic_file.h"
#include "io/camera_file.h"
#include "io/json_io.h"
#include "io/truth_file.h"
#include "scene/scene.h"
#include "scene/sequence.h"

namespace oal {
namespace {

namespace fs = std::filesystem;

constexpr const char* kCameraName = "oal-render";

std::string FrameName(int index, const char* extension) {
  std::string number = std::to_string(index);
  if (number.size() < 4) number.insert(0, 4 - number.size(), '0');
  return "frame_" + number + extension;
}

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
  sampling.max_offset_m = options.max_offset_m;
  sampling.min_visible_length_px = options.min_visible_px;
  sampling.crossings_in_view = options.crossings_margin_px >= 0.0;
  sampling.crossings_margin_px = std::max(0.0, options.crossings_margin_px);
  return sampling;
}

// A renderer file in a data set's folder: frame_NNNN.png, frame_NNNN.json, camera.xml or
// sequence.json (what RenderDataset writes and --overwrite replaces).
bool IsRendererFile(const fs::directory_entry& entry) {
  if (!entry.is_regular_file()) return false;
  const std::string name = entry.path().filename().string();
  if (name == "camera.xml" || name == "sequence.json" || name == "target.yaml") return true;
  const std::string stem = entry.path().stem().string();
  const std::string extension = entry.path().extension().string();
  return (extension == ".png" || extension == ".json") && stem.size() > 6 &&
         stem.compare(0, 6, "frame_") == 0 &&
         stem.find_first_not_of("0123456789", 6) == std::string::npos;
}

std::vector<fs::path> RendererFilesIn(const fs::path& dir) {
  std::vector<fs::path> files;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
    if (IsRendererFile(entry)) files.push_back(entry.path());
  }
  return files;
}

// "20 frames, camera.xml" for the renderer files `files`; empty for none.
std::string DescribeRendererFiles(const std::vector<fs::path>& files) {
  int frames = 0;
  std::string others;
  for (const fs::path& file : files) {
    const std::string name = file.filename().string();
    if (file.extension() == ".png") {
      ++frames;
    } else if (file.extension() != ".json" || name == "sequence.json") {
      others += ", " + name;
    }
  }
  if (frames == 0 && others.empty() && !files.empty()) return "frame_NNNN.json files";
  if (frames == 0) return others.empty() ? "" : others.substr(2);
  return std::to_string(frames) + (frames == 1 ? " frame" : " frames") + others;
}

// The data set's folder, written all or nothing: the frames go to a temporary sibling folder
// `<DIR>.tmp-<pid>`, which Commit() moves into place (one rename when DIR does not exist;
// else the renderer files already in DIR are removed and the new ones moved in, other files
// kept). Without Commit() (an error), the temporary folder and any parent folders created
// for it are removed: nothing is left behind.
class StagedDataset {
 public:
  // Throws std::invalid_argument when DIR is not a folder, or holds renderer files and
  // `overwrite` is false; std::runtime_error when the temporary folder cannot be made.
  StagedDataset(const std::string& out_dir, bool overwrite) : name_(out_dir) {
    target_ = fs::absolute(out_dir).lexically_normal();
    if (!target_.has_filename()) target_ = target_.parent_path();  // "data/", "."
    if (fs::exists(target_) && !fs::is_directory(target_)) {
      throw std::invalid_argument("--out '" + name_ + "' exists and is not a folder");
    }
    if (fs::is_directory(target_) && !overwrite) {
      const std::string held = DescribeRendererFiles(RendererFilesIn(target_));
      if (!held.empty()) {
        throw std::invalid_argument("--out '" + name_ + "' already holds a rendered data set (" +
                                    held +
                                    "); pass --overwrite to replace it (other files in the "
                                    "folder are kept), or choose another folder");
      }
    }
    const fs::path parent = target_.parent_path();
    for (fs::path p = parent; !p.empty() && !fs::exists(p); p = p.parent_path()) created_ = p;
    std::error_code error;
    fs::create_directories(parent, error);
    temp_ = TempPathFor(target_);
    if (!error) fs::remove_all(temp_, error);  // a stale one of an earlier process of this pid
    if (!error) fs::create_directory(temp_, error);
    if (error) {
      RemoveCreatedParents();
      throw std::runtime_error("cannot create the folder '" + temp_.string() + "' for --out '" +
                               name_ + "': " + error.message());
    }
  }

  ~StagedDataset() {
    if (committed_) return;
    std::error_code ignored;
    fs::remove_all(temp_, ignored);
    RemoveCreatedParents();
  }

  StagedDataset(const StagedDataset&) = delete;
  StagedDataset& operator=(const StagedDataset&) = delete;

  /// Where the files are written until Commit().
  const fs::path& dir() const { return temp_; }

  void Commit() {
    if (!fs::exists(target_)) {
      fs::rename(temp_, target_);
    } else {
      for (const fs::path& old : RendererFilesIn(target_)) fs::remove(old);
      // Frames first, then camera.xml, then sequence.json (its presence means complete).
      std::vector<fs::path> files;
      for (const fs::directory_entry& entry : fs::directory_iterator(temp_)) {
        files.push_back(entry.path());
      }
      auto rank = [](const fs::path& file) {
        const std::string name = file.filename().string();
        return std::make_pair(name == "sequence.json" ? 2 : name == "camera.xml" ? 1 : 0, name);
      };
      std::sort(files.begin(), files.end(),
                [&](const fs::path& a, const fs::path& b) { return rank(a) < rank(b); });
      for (const fs::path& file : files) fs::rename(file, target_ / file.filename());
      fs::remove(temp_);
    }
    committed_ = true;
  }

 private:
  // Removes the parent folders the constructor created, if they are (still) empty.
  void RemoveCreatedParents() noexcept {
    if (created_.empty()) return;
    std::error_code error;
    for (fs::path p = target_.parent_path(); !error; p = p.parent_path()) {
      fs::remove(p, error);
      if (p == created_) break;
    }
  }

  std::string name_;  // --out as given, for messages
  fs::path target_;   // absolute, no trailing separator
  fs::path temp_;     // <target>.tmp-<pid>
  fs::path created_;  // the outermost parent folder the constructor created; empty: none
  bool committed_ = false;
};

// Noise seed of frame `index`: distinct per frame, a pure function of the data set's seed.
std::uint64_t NoiseSeed(std::uint64_t seed, int index) {
  return seed ^ (0x9E3779B97F4A7C15ULL * static_cast<std::uint64_t>(index + 1));
}

Json OccluderJson(const Occluder& occluder) {
  const bool disc = occluder.shape == Occluder::Shape::kDisc;
  Json json{{"shape", disc ? "disc" : "rectangle"},
            {"centre", Json::array({occluder.centre_u_px, occluder.centre_v_px})}};
  if (disc) {
    json["radius_px"] = occluder.half_width_px;
  } else {
    json["size_px"] = Json::array({2.0 * occluder.half_width_px, 2.0 * occluder.half_height_px});
  }
  json["grey"] = occluder.grey;
  return json;
}

Json EffectsJson(const FrameEffects& effects) {
  Json occluders = Json::array();
  for (const Occluder& occluder : effects.occluders) occluders.push_back(OccluderJson(occluder));
  return Json{{"gain", effects.gain}, {"offset", effects.offset}, {"occluders", occluders}};
}

// Writes frame_NNNN.png and frame_NNNN.json, each atomically.
void WriteFrame(const fs::path& dir, int index, const RenderedFrame& frame, const Json& truth) {
  const cv::Mat image(static_cast<int>(frame.image.getHeight()),
                      static_cast<int>(frame.image.getWidth()), CV_8UC1, frame.image.bitmap);
  WritePng(dir / FrameName(index, ".png"), image);
  WriteFileAtomically(dir / FrameName(index, ".json"), truth.dump(2) + "\n");
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
  const LineTarget& target = config.target;
  const Sequence sequence =
      MakeSequence(SequenceKindFromString(options.sequence), options.count, options.seed, target);
  const SceneRenderer renderer(sequence.target,
                               SequenceRenderOptions(options, sequence, config.scene));
  const RenderOptions& render = renderer.options();
  SaveCameraFile((dir / "camera.xml").string(), render.camera, kCameraName,
                 static_cast<unsigned int>(render.width), static_cast<unsigned int>(render.height));
  for (int i = 0; i < options.count; ++i) {
    const SequenceFrame& step = sequence.frames[static_cast<std::size_t>(i)];
    const RenderedFrame frame = renderer.Render(step.cMo, step.noise_seed, step.effects);
    Json truth = FrameTruthJson(frame, i, FrameName(i, ".png"), target.name, options.seed,
                                step.noise_seed, render.camera, render.width, render.height);
    for (std::size_t l = 0; l < frame.truth.size(); ++l) {
      truth["lines"][l]["occluded_fraction"] = frame.truth[l].occluded_fraction;
    }
    truth["sequence"] = options.sequence;
    truth["effects"] = EffectsJson(step.effects);
    WriteFrame(dir, i, frame, truth);
  }
  const Json summary{
      {"kind", options.sequence},
      {"seed", options.seed},
      {"count", options.count},
      {"target", target.name},
      {"description", sequence.description},
      {"camera", CameraJson(render.camera, render.width, render.height)},
      {"noise_sigma", render.noise_sigma},
      {"blur_sigma_px", render.blur_sigma_px},
      {"illumination_gradient", render.illumination_gradient},
      {"gradient_angle_rad", render.gradient_angle_rad},
      {"frames", FrameName(0, ".png") + " ... " + FrameName(options.count - 1, ".png")}};
  WriteFileAtomically(dir / "sequence.json", summary.dump(2) + "\n");
}

// Renders independent random poses, their truth and camera.xml into `dir`.
void RenderRandomDataset(const RenderCommandOptions& options, const AppConfig& config,
                         const fs::path& dir) {
  const LineTarget& target = config.target;
  const SceneRenderer renderer(target, ToRenderOptions(options, config.scene));
  const PoseSampling sampling = ToPoseSampling(options);
  const vpCameraParameters& camera = renderer.options().camera;
  SaveCameraFile((dir / "camera.xml").string(), camera, kCameraName,
                 static_cast<unsigned int>(options.width),
                 static_cast<unsigned int>(options.height));
  std::uint64_t state = options.seed;
  for (int i = 0; i < options.count; ++i) {
    const vpHomogeneousMatrix cMo = SamplePose(renderer, sampling, &state);
    const std::uint64_t noise_seed = NoiseSeed(options.seed, i);
    const RenderedFrame frame = renderer.Render(cMo, noise_seed);
    WriteFrame(dir, i, frame,
               FrameTruthJson(frame, i, FrameName(i, ".png"), target.name, options.seed, noise_seed,
                              camera, options.width, options.height));
  }
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
  RequireOption(min_visible_px >= 0.0, "--min-visible-px", min_visible_px, "--min-visible-px >= 0");
  RequireOption(max_offset_m >= 0.0 && max_offset_m <= 100.0, "--max-offset", max_offset_m,
                "0 <= --max-offset <= 100");
  RequireOption(crossings_margin_px >= -1.0 && crossings_margin_px <= 1000.0, "--crossings-margin",
                crossings_margin_px, "-1 <= --crossings-margin <= 1000");
  if (!background_image.empty() && !fs::is_regular_file(background_image)) {
    throw std::invalid_argument("--background image '" + background_image + "' does not exist");
  }
}

vpCameraParameters RenderCamera(int width, int height, double fx_px, double kdu) {
  return CameraWithKdu(fx_px, fx_px, 0.5 * (width - 1), 0.5 * (height - 1), kdu, width, height);
}

int RenderDataset(const RenderCommandOptions& options) {
  options.Check();
  const AppConfig config = ConfigOf(options);
  StagedDataset staged(options.out_dir, options.overwrite);
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
      cli.add_option("--min-visible-px", options.min_visible_px,
                     "every target line visible over at least this length, pixels")
          ->capture_default_str()};
  for (CLI::Option* option : random_pose_options) sequence->excludes(option);
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
