#include "app/render_command.h"

#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include "app/atomic_file.h"
#include "app/camera_file.h"
#include "app/command_line.h"
#include "app/json_io.h"
#include "scene/scene.h"

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

Json TruthJson(const RenderCommandOptions& options, const RenderedFrame& frame, int index,
               std::uint64_t noise_seed, const vpCameraParameters& camera) {
  Json lines = Json::array();
  for (const TruthLine& line : frame.truth) lines.push_back(TruthLineJson(line));
  return Json{{"frame", index},
              {"image", FrameName(index, ".png")},
              {"target", options.target},
              {"seed", options.seed},
              {"noise_seed", noise_seed},
              {"camera", CameraJson(camera, options.width, options.height)},
              {"cMo", PoseJson(frame.cMo)},
              {"lines", std::move(lines)}};
}

}  // namespace

void RenderCommandOptions::Check() const {
  Require(target == "two-line" || target == "four-line", "target", target,
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
  const double u0 = 0.5 * (width - 1), v0 = 0.5 * (height - 1);
  vpCameraParameters camera;
  camera.initPersProjWithDistortion(fx_px, fx_px, u0, v0, 0.0, kdu);
  const double kud = kdu == 0.0 ? 0.0 : FitKud(camera, width, height);
  camera.initPersProjWithDistortion(fx_px, fx_px, u0, v0, kud, kdu);
  return camera;
}

int RenderDataset(const RenderCommandOptions& options) {
  options.Check();
  const SceneRenderer renderer(TargetByName(options.target), ToRenderOptions(options));
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
    const cv::Mat image(static_cast<int>(frame.image.getHeight()),
                        static_cast<int>(frame.image.getWidth()), CV_8UC1, frame.image.bitmap);
    WritePng(dir / FrameName(i, ".png"), image);
    WriteFileAtomically(dir / FrameName(i, ".json"),
                        TruthJson(options, frame, i, noise_seed, camera).dump(2) + "\n");
  }
  return options.count;
}

int RunRender(int argc, char** argv) {
  RenderCommandOptions options;
  CLI::App cli(
      "Render a synthetic data set of a line target with ground truth: DIR/frame_NNNN.png, "
      "DIR/frame_NNNN.json and DIR/camera.xml.",
      "oalservo render");
  cli.add_option("--target", options.target, "two-line or four-line")->capture_default_str();
  cli.add_option("--count", options.count, "number of frames")->capture_default_str();
  cli.add_option("--seed", options.seed, "seed of the poses and the noise")->capture_default_str();
  cli.add_option("--out", options.out_dir, "output directory (created if missing)")->required();
  cli.add_option("--width", options.width, "image width, pixels")->capture_default_str();
  cli.add_option("--height", options.height, "image height, pixels")->capture_default_str();
  cli.add_option("--fx", options.fx_px,
                 "focal length, pixels (fy = fx; principal point at the centre)")
      ->capture_default_str();
  cli.add_option("--kdu", options.kdu, "lens distortion (ViSP kdu; 0.33 is a cheap wide lens)")
      ->capture_default_str();
  cli.add_option("--noise", options.noise_sigma, "Gaussian noise sigma, grey levels")
      ->capture_default_str();
  cli.add_option("--blur", options.blur_sigma_px, "Gaussian blur sigma, pixels")
      ->capture_default_str();
  cli.add_option("--gradient", options.gradient, "illumination fall-off across the image, [0, 0.9]")
      ->capture_default_str();
  cli.add_option("--background", options.background_image, "grey image shown around the board");
  cli.add_option("--min-distance", options.min_distance_m, "camera to board, metres")
      ->capture_default_str();
  cli.add_option("--max-distance", options.max_distance_m, "camera to board, metres")
      ->capture_default_str();
  cli.add_option("--max-tilt-deg", options.max_tilt_deg, "optical axis to board normal, degrees")
      ->capture_default_str();
  cli.add_option("--min-visible-px", options.min_visible_px,
                 "every target line visible over at least this length, pixels")
      ->capture_default_str();
  cli.footer(
      "Example:\n  oalservo render --count 20 --kdu 0.33 --noise 4 --out data/\n"
      "  oalservo detect data/ --camera data/camera.xml --out data/lines.jsonl");
  if (const auto exit = ParseCommandLine(cli, argc, argv)) return *exit;
  const int frames = RenderDataset(options);
  std::cerr << "oalservo render: " << frames << " frames written to " << options.out_dir << '\n';
  return kExitOk;
}

}  // namespace oal
