// The scene a rendered camera sees, as a configuration's `scene:` describes it: the renderer's
// effects in the user's units, and the surface as a photograph's file, read here (scene/
// reads no file).
#pragma once

#include <visp3/core/vpImage.h>

#include <memory>
#include <string>

#include "scene/lived_in.h"
#include "scene/scene.h"

namespace oal {

/// The world a rendered camera sees around the target: the surface the sheet lies on, its
/// light, its shadow, what is printed beside the target and what else lies on the bench
/// (scene/scene.h RenderOptions states each effect), with the surface as an image file.
struct SceneOptions {
  /// An image of the surface (relative paths: relative to the config file); empty: a uniform
  /// grey surface of background_grey.
  std::string background;
  std::string background_origin;      ///< "FILE:LINE" of scene.background, for messages
  double background_texel_m = 0.002;  ///< one background pixel on the plane, m, (0, 1]
  int background_grey = 90;           ///< [0, 255]
  /// The background image's greys become background_gain * grey + background_offset (clipped
  /// to [0, 255]): a darker, paler or flatter surface from the same photograph.
  double background_gain = 1.0;     ///< [0, 4]
  double background_offset = 0.0;   ///< grey levels, [-255, 255]
  double gradient = 0.0;            ///< light falls linearly by this across the image, [0, 0.9]
  double gradient_angle_deg = 0.0;  ///< its direction, degrees, finite
  double vignetting = 0.0;          ///< radial fall-off, [0, 0.9]
  double hot_spot_gain = 0.0;       ///< [0, 2]
  double hot_spot_u = 0.5, hot_spot_v = 0.5;  ///< fractions of width, height, [-2, 3]
  double hot_spot_sigma = 0.4;                ///< fraction of the diagonal, [0.01, 10]
  double shadow_darkness = 0.0;               ///< [0, 0.95]
  double shadow_offset_m = 0.006;             ///< [0, 0.1]
  double shadow_angle_deg = 45.0;             ///< finite
  double shadow_softness_m = 0.003;           ///< [0, 0.05]
  double paper_texture_grey = 0.0;            ///< [0, 20]
  bool annotations = false;                   ///< the target's printed marks
  int clutter_sheets = 0;                     ///< [0, 10]
  int clutter_objects = 0;                    ///< [0, 50]
  double clutter_reach_m = 0.3;               ///< (0, 10]
  int seed = 1;                               ///< the clutter's layout, >= 0
  /// What happens from frame to frame in a lived-in scene (scene.occluders, glare, exposure,
  /// motion_blur, jpeg): drawn per frame by whoever renders the frames (scene/lived_in.h).
  LivedInOptions lived_in;
  /// The servo's simulated camera draws them once for each episode of its run, of a length
  /// drawn in this range (s, 0 < lo <= hi <= 3600), and holds them through it.
  DrawRange episode_s{0.2, 1.0};
  /// The episodes' draws, >= 0 (`oalservo servo-accuracy` adds each start's number).
  int episode_seed = 1;

  /// Copies the effects into `render` and reads the background image. Throws
  /// std::runtime_error "FILE:LINE: scene.background ..." when it cannot be read, and
  /// std::invalid_argument for values RenderOptions::Check() rejects.
  void ApplyTo(RenderOptions* render) const;
  /// `photo` with background_gain and background_offset applied (itself when they are 1, 0).
  std::shared_ptr<const vpImage<unsigned char>> Surface(
      std::shared_ptr<const vpImage<unsigned char>> photo) const;
};

}  // namespace oal
