// Rendered data sets for the evaluations' tests, written through scene/ and io/ as
// `oalservo render` writes them (frames, truth JSON, camera.xml), without the app: the
// evaluations are tested as libraries.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <string>

#include "detector/lens.h"
#include "eval/lines/oal_methods.h"
#include "io/rendered_dataset.h"
#include "io/scene_options.h"
#include "scene/scene.h"
#include "scene/sequence.h"
#include "target/line_target.h"

namespace oal::test {

/// Independent random poses of the paper's four-line board (its lines traverse the image).
struct RandomDataSet {
  int count = 6;
  std::uint64_t seed = 1;
  int width = 640;
  int height = 480;
  double noise_sigma = 0.0;
  double blur_sigma_px = 0.0;
  double max_tilt_deg = 30.0;
  double min_visible_px = 0.0;
  double kdu = 0.0;  ///< ViSP's one-term lens, distorted -> undistorted
  std::string target = "four-line-board";
  std::string background;  ///< an image the target lies on; "": a plain surface
};

/// The surface `render` shows around the target: `background` ("": plain), as `render` does.
inline void ApplySurface(const std::string& background, RenderOptions* render) {
  SceneOptions surface;
  surface.background = background;
  surface.ApplyTo(render);
}

/// `request` rendered into `dir` (a pinhole of 600 px at 640 px wide, scaled with the width);
/// returns `dir`.
inline std::string WriteDataSet(const RandomDataSet& request, const std::filesystem::path& dir) {
  const LineTarget target = TargetByName(request.target);
  RenderOptions render;
  ApplySurface(request.background, &render);
  render.width = request.width;
  render.height = request.height;
  const double fx = 600.0 * request.width / 640.0;
  render.camera = Lens::WithKdu(fx, fx, 0.5 * (request.width - 1), 0.5 * (request.height - 1),
                                request.kdu, request.width, request.height);
  render.noise_sigma = request.noise_sigma;
  render.blur_sigma_px = request.blur_sigma_px;
  PoseSampling sampling;
  sampling.max_tilt_deg = request.max_tilt_deg;
  sampling.min_visible_length_px = request.min_visible_px;
  sampling.max_offset_m = 0.05;
  sampling.crossings_in_view = true;
  sampling.crossings_margin_px = 10.0;
  std::filesystem::create_directories(dir);
  WriteRandomDataset(SceneRenderer(target, render), sampling, request.count,
                     DatasetLabels{target.name, request.seed, "oal-render"}, dir);
  return dir.string();
}

/// `count` frames of the scripted sequence `kind` (scene/sequence.h) of `target`, into `dir`.
inline std::string WriteSequence(const std::string& kind, int count, std::uint64_t seed,
                                 const std::filesystem::path& dir,
                                 const std::string& target = "four-line-board",
                                 const std::string& background = "") {
  const Sequence sequence =
      MakeSequence(SequenceKindFromString(kind), count, seed, TargetByName(target));
  RenderOptions render = sequence.options;
  ApplySurface(background, &render);
  std::filesystem::create_directories(dir);
  render.illumination_gradient = sequence.options.illumination_gradient;
  render.gradient_angle_rad = sequence.options.gradient_angle_rad;
  WriteSequenceDataset(sequence, kind, SceneRenderer(sequence.target, render),
                       DatasetLabels{sequence.target.name, seed, "oal-render"}, dir);
  return dir.string();
}

/// Our detector's default setup tracking `target`'s lines, as the evaluations take it.
inline TrackerSetup SetupFor(const std::string& target) {
  TrackerSetup setup;
  setup.target = TargetByName(target);
  setup.target_origin = "test";
  return setup;
}

}  // namespace oal::test
