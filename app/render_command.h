// `oalservo render`: a synthetic data set with ground truth, laid out as io/rendered_dataset.h
// describes, so that `oalservo detect DIR --camera DIR/camera.xml` runs on it; DIR/target.yaml
// is the target rendered, as a config's `target:` section (`pose DIR` and `evaluate DIR` read
// it). With `--sequence KIND` (scene/sequence.h) the frames are a reproducible camera motion
// with per-frame effects instead of independent random poses. All or nothing; a DIR that
// already holds a data set is refused unless `overwrite`, which replaces the data set's files
// and keeps any other file in DIR.
#pragma once

#include <cstdint>
#include <string>

#include "detector/lens.h"

namespace oal {

struct RenderCommandOptions {
  /// Empty: independent random poses from the options below. Otherwise a sequence name
  /// (SequenceKindNames()); the sequence then sets the image size, camera, noise, blur,
  /// illumination and poses, and only target, count, seed and out_dir are used.
  std::string sequence;
  /// A built-in target: one of TargetNames() (scene/scene.h), or "four-line", an older name
  /// of "four-line-board".
  std::string target = "four-line-a3";
  /// YAML file whose `target:` section gives the target instead of `target`, and whose
  /// `scene:` section the surface, light, shadow and clutter (app/config.h); empty: use
  /// `target` and a plain grey surface. The data set's JSON then names the config's target.
  std::string config;
  int count = 10;          ///< frames, [1, 100000]
  std::uint64_t seed = 1;  ///< poses and noise are a function of it
  std::string out_dir;     ///< created if missing; required
  /// Replace the renderer files already in out_dir; false: such a folder is an error.
  bool overwrite = false;
  int width = 640;       ///< pixels, [16, 8192]
  int height = 480;      ///< pixels, [16, 8192]
  double fx_px = 600.0;  ///< focal length, pixels (fy = fx), > 0
  double kdu = 0.0;      ///< ViSP distortion, distorted -> undistorted; 0: none
  /// A ViSP camera file to render through instead (its px, py, u0, v0, kdu and, when it has
  /// one, its image size); fx_px and kdu are then unused. Empty: none.
  std::string camera_path;
  double noise_sigma = 0.0;    ///< Gaussian noise, grey levels, [0, 100]
  double blur_sigma_px = 0.0;  ///< Gaussian blur, pixels, [0, 20]
  double gradient = 0.0;       ///< illumination fall-off across the image, [0, 0.9]
  /// Grey image of the surface around the board (replaces the config's scene.background);
  /// empty: the config's, else uniform.
  std::string background_image;
  double min_distance_m = 0.4;  ///< camera to board, metres, > 0
  double max_distance_m = 0.9;  ///< metres, >= min_distance_m
  double max_tilt_deg = 30.0;   ///< optical axis to board normal, degrees, [0, 80]
  double min_tilt_deg = 0.0;    ///< ... at least, [0, max_tilt_deg]
  double min_visible_px = 0.0;  ///< each line's visible length at least this, pixels
  /// Where the optical axis meets the board, at most this far from its centre, metres, >= 0.
  double max_offset_m = 0.05;
  /// A '#' target's four crossings (each square where two stripes cross) at least this far
  /// inside the image, pixels; < 0: not required. [-1, 1000].
  double crossings_margin_px = 10.0;

  /// Throws std::invalid_argument naming the command-line option (`--fx`), its value and
  /// the violated constraint.
  void Check() const;
};

/// The camera of a rendered data set: fx = fy = `fx_px`, principal point at the image centre
/// ((w-1)/2, (h-1)/2), model perspectiveProjWithDistortion with `kdu` and kud = FitKud().
Lens RenderCamera(int width, int height, double fx_px, double kdu);

/// Frames of a sequence when `--sequence` is given without `--count`.
constexpr int kDefaultSequenceFrames = 60;

/// Renders options.count frames into options.out_dir, all or nothing (see above). Returns the
/// number of frames written; throws on bad options, a folder holding a data set without
/// `overwrite`, a failed pose sampling or I/O errors, leaving no file behind.
int RenderDataset(const RenderCommandOptions& options);

/// `oalservo render ...`; argv[0] is "render".
int RunRender(int argc, char** argv);

}  // namespace oal
