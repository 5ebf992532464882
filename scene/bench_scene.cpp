#include "scene/bench_scene.h"

namespace oal {

void DressAsBench(RenderOptions* render, std::uint64_t scene_seed) {
  render->vignetting = 0.3;
  render->shadow_darkness = 0.3;
  render->paper_texture_grey = 3.0;
  render->annotations = true;
  render->clutter_sheets = 2;
  render->clutter_objects = 4;
  render->clutter_reach_m = 0.25;
  render->scene_seed = scene_seed;
}

bool IsSheet(const LineTarget& target) {
  return target.board_width_m <= 1.0 && target.board_height_m <= 1.0;
}

PoseSampling SheetSampling(const LineTarget& target) {
  double near_m = 0.3, far_m = 0.85;
  if (target.name == "four-line-a4" || target.name == "four-line-letter") {
    near_m = 0.25;
    far_m = 0.6;
  } else if (target.name != "four-line-a3") {
    const double scale = target.board_width_m / 0.42;
    near_m *= scale;
    far_m *= scale;
  }
  PoseSampling sampling;
  sampling.min_distance_m = near_m;
  sampling.max_distance_m = far_m;
  sampling.max_tilt_deg = 30.0;
  sampling.max_offset_m = 0.1;
  sampling.crossings_in_view = true;
  sampling.crossings_margin_px = 10.0;
  return sampling;
}

}  // namespace oal
