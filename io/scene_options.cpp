#include "io/scene_options.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>

#include "base/angles.h"
#include "io/image_source.h"

namespace oal {

void SceneOptions::ApplyTo(RenderOptions* render) const {
  render->background_texel_m = background_texel_m;
  render->background_grey = background_grey;
  render->illumination_gradient = gradient;
  render->gradient_angle_rad = gradient_angle_deg * kRadPerDeg;
  render->vignetting = vignetting;
  render->hot_spot_gain = hot_spot_gain;
  render->hot_spot_u = hot_spot_u;
  render->hot_spot_v = hot_spot_v;
  render->hot_spot_sigma = hot_spot_sigma;
  render->shadow_darkness = shadow_darkness;
  render->shadow_offset_m = shadow_offset_m;
  render->shadow_angle_rad = shadow_angle_deg * kRadPerDeg;
  render->shadow_softness_m = shadow_softness_m;
  render->paper_texture_grey = paper_texture_grey;
  render->annotations = annotations;
  render->clutter_sheets = clutter_sheets;
  render->clutter_objects = clutter_objects;
  render->clutter_reach_m = clutter_reach_m;
  render->scene_seed = static_cast<std::uint64_t>(seed);
  render->background.reset();
  if (background.empty()) return;
  const std::string where = (background_origin.empty() ? "" : background_origin + ": ") +
                            "background image '" + background + "'";
  try {
    render->background = Surface(ReadGrayImage(background));
  } catch (const std::runtime_error& error) {
    throw std::runtime_error(where + ": " + error.what());
  }
}

std::shared_ptr<const vpImage<unsigned char>> SceneOptions::Surface(
    std::shared_ptr<const vpImage<unsigned char>> photo) const {
  if (background_gain == 1.0 && background_offset == 0.0) return photo;
  auto surface = std::make_shared<vpImage<unsigned char>>(*photo);
  for (unsigned int i = 0; i < surface->getSize(); ++i) {
    const long grey = std::lround(background_gain * surface->bitmap[i] + background_offset);
    surface->bitmap[i] = static_cast<unsigned char>(std::clamp(grey, 0L, 255L));
  }
  return surface;
}

}  // namespace oal
