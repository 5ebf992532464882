#include "eval/rendered/rendered_frames.h"

#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "base/check.h"
#include "base/random.h"
#include "detector/lens.h"
#include "io/image_source.h"
#include "io/json_io.h"

namespace oal {
namespace {

constexpr const char* kVispImages = "/usr/share/visp-images-data/ViSP-images";

}  // namespace

double Uniform01(std::uint64_t seed, int frame, std::uint64_t stream) {
  return UnitInterval(SplitMixFinal(seed * 0x9E3779B97F4A7C15ULL +
                                    static_cast<std::uint64_t>(frame) * 0xBF58476D1CE4E5B9ULL +
                                    stream));
}

void RenderedFrameOptions::Check() const {
  RequireOption(frames >= 1 && frames <= 1000000, "RenderedFrameOptions::frames", frames,
                "1 <= frames <= 1000000");
  RequireOption(first_frame >= 0 && first_frame <= 1000000, "RenderedFrameOptions::first_frame",
                first_frame, "0 <= first_frame <= 1000000");
  RequireOption(kdu > -1.0 && kdu < 1.0, "RenderedFrameOptions::kdu", kdu, "-1 < kdu < 1");
  RequireOption(noise_sigma >= 0.0 && noise_sigma <= 100.0, "RenderedFrameOptions::noise_sigma",
                noise_sigma, "0 <= noise_sigma <= 100");
  RequireOption(blur_sigma_px >= 0.0 && blur_sigma_px <= 20.0,
                "RenderedFrameOptions::blur_sigma_px", blur_sigma_px, "0 <= blur_sigma_px <= 20");
  RequireOption(illumination_gradient >= 0.0 && illumination_gradient <= 0.9,
                "RenderedFrameOptions::illumination_gradient", illumination_gradient,
                "0 <= illumination_gradient <= 0.9");
  RequireOption(width >= 16 && height >= 16, "RenderedFrameOptions::width, height",
                std::to_string(width) + "x" + std::to_string(height), "both >= 16");
  RequireOption(focal_px > 0.0 && std::isfinite(focal_px), "RenderedFrameOptions::focal_px",
                focal_px, "focal_px > 0");
  RequireOption(noise_max <= 100.0, "RenderedFrameOptions::noise_max", noise_max,
                "noise_max <= 100");
  RequireOption(blur_max_px <= 20.0, "RenderedFrameOptions::blur_max_px", blur_max_px,
                "blur_max_px <= 20");
  RequireOption(width <= 8192 && height <= 8192, "RenderedFrameOptions::width, height",
                std::to_string(width) + "x" + std::to_string(height), "both <= 8192");
  scene.lived_in.Check();
}

RenderOptions MakeRenderOptions(const RenderedFrameOptions& options) {
  RenderOptions render;
  render.width = options.width;
  render.height = options.height;
  render.camera =
      Lens::WithKdu(options.focal_px, options.focal_px, 0.5 * (options.width - 1),
                    0.5 * (options.height - 1), options.kdu, options.width, options.height);
  if (options.camera) render.camera = *options.camera;
  SceneOptions scene = options.scene;
  scene.background.clear();  // EvaluationScenes reads them
  scene.ApplyTo(&render);
  render.noise_sigma = options.noise_sigma;
  render.blur_sigma_px = options.blur_sigma_px;
  if (options.illumination_gradient > 0.0)
    render.illumination_gradient = options.illumination_gradient;
  return render;
}

EvaluationScenes::EvaluationScenes(const LineTarget& target, const RenderedFrameOptions& options,
                                   const PrintedPicture& picture)
    : options_(options), target_(target) {
  std::vector<std::string> paths = options.backgrounds;
  if (paths.empty() && !options.scene.background.empty()) paths = {options.scene.background};
  RenderOptions base = MakeRenderOptions(options);
  base.printed_picture = picture;
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
  DrawLivedIn(options_.scene.lived_in, target_, options_.seed, frame, &effects);
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
          " is missing): install it (scripts/install-deps.sh) or give a background image of "
          "your own");
    }
    paths.push_back(path);
  }
  return paths;
}

nlohmann::json RenderedFrameJson(const RenderedFrameOptions& options) {
  nlohmann::json json{{"frames", options.frames},
                      {"first_frame", options.first_frame},
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
  if (options.camera) {
    json["camera"] = CameraJson(*options.camera, options.width, options.height);
  }
  if (options.scene.lived_in.Any()) {
    const LivedInOptions& l = options.scene.lived_in;
    json["lived_in"] = {{"occluders", l.occluders.fraction},
                        {"glare", l.glare.fraction},
                        {"exposure", l.exposure.fraction},
                        {"motion_blur", l.motion_blur.fraction},
                        {"jpeg", l.jpeg.fraction}};
  }
  return json;
}

// scene/bench_scene.h's DressAsBench() as a config (the benchmarks and tests render it so).
SceneOptions BenchScene() {
  SceneOptions scene;
  scene.vignetting = 0.3;
  scene.shadow_darkness = 0.3;
  scene.paper_texture_grey = 3.0;
  scene.annotations = true;
  scene.clutter_sheets = 2;
  scene.clutter_objects = 4;
  scene.clutter_reach_m = 0.25;
  return scene;
}

}  // namespace oal
