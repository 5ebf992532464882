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

}  // namespace oal
