#include "app/render_command.h"

#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/atomic_file.h"
#include "app/camera_file.h"
#include "app/command_line.h"
#include "app/config.h"
#include "app/json_io.h"
#include "scene/scene.h"
#include "scene/sequence.h"

namespace oal {
namespace {

namespace fs = std::filesystem;

constexpr const char* kCameraName = "oal-render";

template <typename T>
void Require(bool ok, const char* field, const T& value, const char* constraint) {
  if (ok) return;
  std::ostringstream message;
  message << "RenderCommandOptions::" << field << " = " << value
          << ". Violated constraint: " << constraint;
  throw std::invalid_argument(message.str());
}

std::string FrameName(int index, const char* extension) {
  std::string number = std::to_string(index);
  if (number.size() < 4) number.insert(0, 4 - number.size(), '0');
  return "frame_" + number + extension;
}

RenderOptions ToRenderOptions(const RenderCommandOptions& options) {
  RenderOptions render;
  render.width = options.width;
  render.height = options.height;
  render.camera = RenderCamera(options.width, options.height, options.fx_px, options.kdu);
  render.noise_sigma = options.noise_sigma;
  render.blur_sigma_px = options.blur_sigma_px;
  render.illumination_gradient = options.gradient;
  render.background_image = options.background_image;
  return render;
}

PoseSampling ToPoseSampling(const RenderCommandOptions& options) {
  PoseSampling sampling;
  sampling.min_distance_m = options.min_distance_m;
  sampling.max_distance_m = options.max_distance_m;
  sampling.max_tilt_deg = options.max_tilt_deg;
  sampling.min_visible_length_px = options.min_visible_px;
  return sampling;
}

// Noise seed of frame `index`: distinct per frame, a pure function of the data set's seed.
std::uint64_t NoiseSeed(std::uint64_t seed, int index) {
  return seed ^ (0x9E3779B97F4A7C15ULL * static_cast<std::uint64_t>(index + 1));
}

Json TruthJson(const std::string& target, std::uint64_t seed, const RenderedFrame& frame, int index,
               std::uint64_t noise_seed, const vpCameraParameters& camera, int width, int height) {
  Json lines = Json::array();
  for (const TruthLine& line : frame.truth) lines.push_back(TruthLineJson(line));
  return Json{{"frame", index},
              {"image", FrameName(index, ".png")},
              {"target", target},
              {"seed", seed},
              {"noise_seed", noise_seed},
              {"camera", CameraJson(camera, width, height)},
              {"cMo", PoseJson(frame.cMo)},
              {"lines", std::move(lines)}};
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

// The target to render: the config's `target:` section if a config is given, else by name.
LineTarget TargetOf(const RenderCommandOptions& options) {
  return options.config.empty() ? TargetByName(options.target) : LoadConfig(options.config).target;
}

int RenderSequenceDataset(const RenderCommandOptions& options, const LineTarget& target) {
  const Sequence sequence =
      MakeSequence(SequenceKindFromString(options.sequence), options.count, options.seed, target);
  const SceneRenderer renderer(sequence.target, sequence.options);
  const RenderOptions& render = renderer.options();
  const fs::path dir(options.out_dir);
  fs::create_directories(dir);
  SaveCameraFile((dir / "camera.xml").string(), render.camera, kCameraName,
                 static_cast<unsigned int>(render.width), static_cast<unsigned int>(render.height));
  for (int i = 0; i < options.count; ++i) {
    const SequenceFrame& step = sequence.frames[static_cast<std::size_t>(i)];
    const RenderedFrame frame = renderer.Render(step.cMo, step.noise_seed, step.effects);
    Json truth = TruthJson(target.name, options.seed, frame, i, step.noise_seed, render.camera,
                           render.width, render.height);
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
  return options.count;
}

}  // namespace

void RenderCommandOptions::Check() const {
  if (!sequence.empty()) {
    try {
      SequenceKindFromString(sequence);
    } catch (const std::invalid_argument&) {
      Require(false, "sequence", sequence, ("sequence is one of: " + SequenceKindNames()).c_str());
    }
  }
  Require(!config.empty() || target == "two-line" || target == "four-line", "target", target,
          "target is two-line or four-line");
  Require(count >= 1 && count <= 100000, "count", count, "1 <= count <= 100000");
  Require(!out_dir.empty(), "out_dir", "''", "an output directory is given");
  Require(width >= 16 && width <= 8192, "width", width, "16 <= width <= 8192");
  Require(height >= 16 && height <= 8192, "height", height, "16 <= height <= 8192");
  Require(fx_px > 0.0 && fx_px <= 1e5, "fx_px", fx_px, "0 < fx_px <= 1e5");
  Require(kdu > -1.0 && kdu < 1.0, "kdu", kdu, "-1 < kdu < 1");
  Require(noise_sigma >= 0.0 && noise_sigma <= 100.0, "noise_sigma", noise_sigma,
          "0 <= noise_sigma <= 100");
  Require(blur_sigma_px >= 0.0 && blur_sigma_px <= 20.0, "blur_sigma_px", blur_sigma_px,
          "0 <= blur_sigma_px <= 20");
  Require(gradient >= 0.0 && gradient <= 0.9, "gradient", gradient, "0 <= gradient <= 0.9");
  Require(min_distance_m > 0.0, "min_distance_m", min_distance_m, "min_distance_m > 0");
  Require(max_distance_m >= min_distance_m, "max_distance_m", max_distance_m,
          "max_distance_m >= min_distance_m");
  Require(max_tilt_deg >= 0.0 && max_tilt_deg <= 80.0, "max_tilt_deg", max_tilt_deg,
          "0 <= max_tilt_deg <= 80");
  Require(min_visible_px >= 0.0, "min_visible_px", min_visible_px, "min_visible_px >= 0");
  if (!background_image.empty() && !fs::is_regular_file(background_image)) {
    throw std::invalid_argument("background image '" + background_image + "' does not exist");
  }
}

vpCameraParameters RenderCamera(int width, int height, double fx_px, double kdu) {
  return CameraWithKdu(fx_px, fx_px, 0.5 * (width - 1), 0.5 * (height - 1), kdu, width, height);
}

int RenderDataset(const RenderCommandOptions& options) {
  options.Check();
  const LineTarget target = TargetOf(options);
  if (!options.sequence.empty()) return RenderSequenceDataset(options, target);
  const SceneRenderer renderer(target, ToRenderOptions(options));
  const PoseSampling sampling = ToPoseSampling(options);
  const vpCameraParameters& camera = renderer.options().camera;
  const fs::path dir(options.out_dir);
  fs::create_directories(dir);
  SaveCameraFile((dir / "camera.xml").string(), camera, kCameraName,
                 static_cast<unsigned int>(options.width),
                 static_cast<unsigned int>(options.height));
  std::uint64_t state = options.seed;
  for (int i = 0; i < options.count; ++i) {
    const vpHomogeneousMatrix cMo = SamplePose(renderer, sampling, &state);
    const std::uint64_t noise_seed = NoiseSeed(options.seed, i);
    const RenderedFrame frame = renderer.Render(cMo, noise_seed);
    WriteFrame(dir, i, frame,
               TruthJson(target.name, options.seed, frame, i, noise_seed, camera, options.width,
                         options.height));
  }
  return options.count;
}

int RunRender(int argc, char** argv) {
  RenderCommandOptions options;
  CLI::App cli(
      "Render a synthetic data set of a line target with ground truth: DIR/frame_NNNN.png, "
      "DIR/frame_NNNN.json and DIR/camera.xml.",
      "oalservo render");
  CLI::Option* sequence = cli.add_option(
      "--sequence", options.sequence,
      "render a reproducible sequence instead of random poses: " + SequenceKindNames() +
          " (sets size, camera, noise, blur and poses)");
  CLI::Option* target =
      cli.add_option("--target", options.target, "two-line or four-line")->capture_default_str();
  cli.add_option("--config", options.config,
                 "YAML file whose 'target:' section gives the target (instead of --target)")
      ->excludes(target);
  CLI::Option* count = cli.add_option("--count", options.count,
                                      "number of frames (default with --sequence: " +
                                          std::to_string(kDefaultSequenceFrames) + ")")
                           ->capture_default_str();
  cli.add_option("--seed", options.seed, "seed of the poses and the noise")->capture_default_str();
  cli.add_option("--out", options.out_dir, "output directory (created if missing)")->required();
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
      cli.add_option("--background", options.background_image, "grey image shown around the board"),
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
      "Examples:\n  oalservo render --count 20 --kdu 0.33 --noise 4 --out data/\n"
      "  oalservo detect data/ --camera data/camera.xml --out data/lines.jsonl\n"
      "  oalservo render --sequence fast --count 60 --seed 1 --out fast/");
  if (const auto exit = ParseCommandLine(cli, argc, argv)) return *exit;
  if (!options.sequence.empty() && count->count() == 0) options.count = kDefaultSequenceFrames;
  const int frames = RenderDataset(options);
  std::cerr << "oalservo render: " << frames << " frames"
            << (options.sequence.empty() ? "" : " of sequence '" + options.sequence + "'")
            << " written to " << options.out_dir << '\n';
  return kExitOk;
}

}  // namespace oal
