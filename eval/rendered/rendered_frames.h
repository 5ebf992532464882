// The rendered frames the accuracy evaluations run on (detect-accuracy, pose-accuracy,
// calibrate-accuracy): how many, their seed, camera and degradations, the benches the target
// lies on, and each frame's effects, reproducible from the seed.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "detector/lens.h"
#include "io/scene_options.h"
#include "scene/scene.h"
#include "target/line_target.h"

namespace oal {

/// The rendered frames of an accuracy evaluation: how many, their seed, camera and degradations.
struct RenderedFrameOptions {
  int frames = 1000;  ///< rendered frames, [1, 1000000]
  /// The first of them in the seed's sequence, [0, 1000000]: the poses before it are drawn
  /// (each frame's pose follows from the one before) but not rendered, so frame N of a long
  /// run is replayed on its own, exactly as it was.
  int first_frame = 0;
  std::uint64_t seed = 1;  ///< poses and noise
  int width = 640, height = 480;
  double focal_px = 600.0;
  double kdu = 0.33;  ///< cheap wide lens (barrel, k1 ≈ -0.25)
  /// A camera to render through instead (its own px, py, u0, v0 and kdu; `oalservo
  /// calibrate-accuracy`'s off-centre cameras); focal_px and kdu are then unused.
  std::optional<Lens> camera;
  double noise_sigma = 8.0;  ///< grey levels
  /// Each frame's noise drawn uniformly in [noise_sigma, noise_max] (from the seed); below
  /// noise_sigma: every frame noise_sigma.
  double noise_max = -1.0;
  double blur_sigma_px = 1.0;
  double blur_max_px = -1.0;  ///< as noise_max, for the blur
  double illumination_gradient = 0.2;
  /// Images of the surface the board lies on, one after the other from frame to frame (paths);
  /// empty: the scene's (below), else a uniform grey surface.
  std::vector<std::string> backgrounds;
  /// The surface, light, shadow, annotations and clutter (a config's `scene:`); its
  /// background is used when `backgrounds` is empty.
  SceneOptions scene;

  /// Throws std::invalid_argument naming the command-line option and its range: --frames
  /// [1, 1000000], --first-frame [0, 1000000], --kdu (-1, 1) (as `oalservo render`), --noise
  /// [0, 100], --blur [0, 20], --gradient [0, 0.9]; and width, height >= 16, focal_px > 0.
  void Check() const;
};

/// A uniform number in [0, 1) from a seed, a frame and a stream (SplitMix64): what each
/// frame's effects and an evaluation's other draws are made of, reproducible from the seed.
double Uniform01(std::uint64_t seed, int frame, std::uint64_t stream);

/// The renderer's options for `options`: a centred camera with focal_px and kdu, noise, blur,
/// and the scene (without its background).
RenderOptions MakeRenderOptions(const RenderedFrameOptions& options);

/// The renderers of an evaluation, one per background (or one), and each frame's effects.
class EvaluationScenes {
 public:
  /// Reads the backgrounds; throws std::runtime_error naming an unreadable one. `picture` is
  /// printed on the target's board (RenderOptions::printed_picture; none by default).
  EvaluationScenes(const LineTarget& target, const RenderedFrameOptions& options,
                   const PrintedPicture& picture = PrintedPicture());
  /// The renderer of frame `frame` (backgrounds in turn).
  const SceneRenderer& For(int frame) const;
  /// Frame `frame`'s noise and blur, and the scene's lived-in conditions (FrameEffects),
  /// drawn from `seed` and the frame.
  FrameEffects EffectsFor(int frame) const;
  /// "Klimt.pgm" etc., or "uniform grey", for frame `frame`.
  std::string BackgroundName(int frame) const;

 private:
  RenderedFrameOptions options_;
  LineTarget target_;
  std::vector<SceneRenderer> renderers_;
  std::vector<std::string> names_;
};

/// The photographs of Debian's visp-images-data used as benches by default for the sheet
/// targets (a painting, a desk with a printed sheet, a crowd outdoors, a cluttered lab, a
/// dark room, a comic-strip collage, a room with a cube): paths that exist when the package is
/// installed. Throws std::runtime_error saying so when it is not.
std::vector<std::string> DefaultBenchPhotos();

/// `options` as JSON, the start of a report's "options" object (each command adds its own).
nlohmann::json RenderedFrameJson(const RenderedFrameOptions& options);

/// The bench a sheet target is evaluated on unless a config's `scene:` says otherwise: the
/// sheet printed with its annotations, its texture and soft shadow, two printed text sheets
/// and four tools around it, light falling off towards the corners (the photographs under it
/// are DefaultBenchPhotos()).
SceneOptions BenchScene();

}  // namespace oal
