// Synthetic scenes for testing and simulation: planar line targets seen by a pinhole camera
// with ViSP's lens model, rendered with ground truth.
//
// Frames: the target (object) frame o has the board in its z = 0 plane, centred on the
// origin; the camera frame c has z along the optical axis, x to the right, y down (ViSP).
// cMo maps object coordinates to camera coordinates.
//
// Lens: the image is formed with ViSP's `kdu` model, i.e. a distorted pixel (u, v) sees the
// ray x = (u - u0)(1 + kdu r^2)/px, y = (v - v0)(1 + kdu r^2)/py with r^2 from the distorted
// pixel (vpPixelMeterConversion). A camera calibrated with that kdu undistorts the frames
// exactly; kud is only written for ViSP's metre -> pixel direction. A cheap wide lens is
// kdu ≈ +0.33 at 640x480, px = 600 (barrel, k1 ≈ -0.25 in the undistorted -> distorted sense).
//
// Rendering: each pixel integrates the scene over its square (box filter). A pixel crossed by
// one edge, or by the two sides of one stripe, gets its exact coverage from the local affine
// map pixel -> board plane; a pixel where edges meet (corners, crossings, stripe ends) is split
// into supersample x supersample sub-squares treated the same way. The board is printed on both
// sides; the camera sees its front when the object z axis points away from the camera.
//
// Scene dressing (RenderOptions: the surface's image, clutter, the board's shadow, the paper's
// texture and annotations, a printed picture) is sampled where the pixel centre's ray meets the
// plane, pictures through an area-averaged pyramid chosen by the pixel's footprint (a printed
// picture's texels, larger than a pixel, as sharp squares) and objects anti-aliased from their
// distance to the pixel centre: close to, not exactly, a box filter. The stripes and the
// board's edges stay exact, and the ground truth never depends on the dressing.
#pragma once

#include <visp3/core/vpHomogeneousMatrix.h>
#include <visp3/core/vpImage.h>

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "detector/lens.h"  // DistortedPixel, FitKud, CameraWithKdu
#include "detector/line.h"
#include "target/line_target.h"

namespace oal {

/// A picture printed on the paper, instead of the stripes or beside them (a marker users would
/// print instead of ours: an AprilTag, a ChArUco board). Texel grey g lays the target's ink
/// (LineTarget::line_grey) over the fraction 1 - g / 255 of its square and lets the paper (its
/// grey and texture) show through the rest: 0 is full ink, 255 bare paper. Centred on the
/// board's origin, its columns along the object x axis and its rows along y: texel (column i,
/// row j) covers x in [-w/2 + i t, -w/2 + (i + 1) t] and y in [-h/2 + j t, -h/2 + (j + 1) t],
/// t = width_m / columns (texels square), w and h its width and height. Each texel is printed
/// as a sharp square, as a marker is scaled for print (no smoothing between texels); a pixel
/// sees the mean of the texels under it through the area-averaged pyramid of the other
/// pictures on the plane. The annotations keep clear of it; the ground truth is unchanged.
struct PrintedPicture {
  /// Grey, any size; null or empty: no picture. Shared, not copied, by copies of the options
  /// and by the renderer.
  std::shared_ptr<const vpImage<unsigned char>> image;
  double width_m = 0.0;  ///< its width along x, metres, (0, 100] with a picture

  bool empty() const { return image == nullptr || image->getSize() == 0; }
};

struct RenderOptions {
  int width = 640;                                          ///< pixels, [16, 8192]
  int height = 480;                                         ///< pixels, [16, 8192]
  Lens camera = Lens::Pinhole(600.0, 600.0, 319.5, 239.5);  ///< with or without distortion
  double noise_sigma = 0.0;    ///< Gaussian noise, grey levels, [0, 100]
  double blur_sigma_px = 0.0;  ///< Gaussian blur, pixels, [0, 20]
  /// Illumination falls linearly by this fraction across the image along gradient_angle_rad.
  double illumination_gradient = 0.0;  ///< [0, 0.9]
  double gradient_angle_rad = 0.0;

  // The surface the board lies on. ------------------------------------------------------------
  /// Grey image of the surface around the board (any size; null or empty: uniform
  /// background_grey). It is pasted on the board plane around the board: texel (column i,
  /// row j) is seen at the plane point (X, Y) = (i, j) * background_texel_m (object frame),
  /// interpolated bilinearly in between and tiled in both directions, so it moves with the
  /// board; rays that miss the plane see background_grey. Shared, not copied, by copies of the
  /// options and by the renderer.
  std::shared_ptr<const vpImage<unsigned char>> background;
  double background_texel_m = 0.002;  ///< size of one background texel on the plane, m, (0, 1]
  int background_grey = 90;           ///< [0, 255]
  int supersample = 4;                ///< anti-aliasing factor per axis where edges meet, [1, 8]

  // Light fall-off, applied with the illumination gradient (after occluders, before gain). -----
  /// Vignetting: brightness times 1 - vignetting * (r / r_corner)^2, r the distance of the pixel
  /// from the principal point (u0, v0) and r_corner that of the farthest image corner. 0: none.
  double vignetting = 0.0;  ///< [0, 0.9]
  /// A broad light spot: brightness times 1 + hot_spot_gain * exp(-d^2 / (2 s^2)), d the pixel's
  /// distance from (hot_spot_u * (width - 1), hot_spot_v * (height - 1)) and s = hot_spot_sigma
  /// times the image diagonal. 0: none.
  double hot_spot_gain = 0.0;   ///< [0, 2]
  double hot_spot_u = 0.5;      ///< centre, fraction of the image width (0: column 0), [-2, 3]
  double hot_spot_v = 0.5;      ///< centre, fraction of the image height (0: row 0), [-2, 3]
  double hot_spot_sigma = 0.4;  ///< width, fraction of the image diagonal, [0.01, 10]

  // Shadow of the board on the surface. -------------------------------------------------------
  /// The board lies a little above the surface (or a lamp is low): the board's outline moved by
  /// shadow_offset_m along shadow_angle_rad darkens the surface inside it by the factor
  /// 1 - shadow_darkness, seen as a band of about shadow_offset_m outside the board's edges
  /// that face that direction. It falls on the surface and what lies on it, never on the
  /// board. 0: no shadow.
  double shadow_darkness = 0.0;    ///< [0, 0.95]
  double shadow_offset_m = 0.006;  ///< metres on the plane, [0, 0.1]
  /// Direction of the shadow's offset in the object frame, from +x towards +y, radians, finite
  /// (pi/4: the band lies along the board's +x and +y edges).
  double shadow_angle_rad = 0.7853981633974483;
  /// Penumbra: the shadow's edge ramps linearly over this width on the plane, metres, [0, 0.05]
  /// (at least one pixel's footprint, so a hard shadow is still anti-aliased).
  double shadow_softness_m = 0.003;

  // Paper and ink. -----------------------------------------------------------------------------
  /// The paper's grey varies smoothly by up to +-paper_texture_grey grey levels (value noise on
  /// 1 mm cells fixed to the board, from scene_seed); the stripes' ink does not. 0: uniform.
  double paper_texture_grey = 0.0;  ///< grey levels, [0, 20]
  /// Printed annotations on the board, as `oalservo target` prints them in the paper between
  /// the stripes: the line numbers 1-4 beside both ends of each stripe, the target's name and
  /// "print at 100 %" near the board's top-left corner, a 100 mm scale bar with 10 mm ticks
  /// (50 mm where 100 mm does not fit) near its bottom-left corner, in OpenCV's Hershey font.
  /// Strokes about 0.4 mm, capitals 3 mm high; every mark is at least 5 mm clear of every
  /// stripe and 4 mm inside the board (a mark that does not fit is left out). An approximation
  /// of the printed layout, not a copy of it. The ground truth is unchanged.
  bool annotations = false;
  int annotation_grey = 110;  ///< the annotations' ink, [0, 255]

  // A picture printed on the board. -----------------------------------------------------------
  /// None by default (PrintedPicture: a marker users would print instead of the stripes).
  PrintedPicture printed_picture;

  // Clutter on the surface, outside the board. ------------------------------------------------
  /// Other printed sheets (A4 and A5, light paper with rows of dark text) and dark objects
  /// (tools: bars, blocks and discs) lying on the surface at random positions and angles drawn
  /// from scene_seed: each lies within clutter_reach_m of the board's outline and at least
  /// 10 mm away from the board (an item that finds no place in 100 draws is left out); sheets
  /// first, objects on top. The ground truth is unchanged.
  int clutter_sheets = 0;        ///< [0, 10]
  int clutter_objects = 0;       ///< [0, 50]
  double clutter_reach_m = 0.3;  ///< metres, (0, 10]
  std::uint64_t scene_seed = 1;  ///< the clutter's layout and the paper's texture

  /// Throws std::invalid_argument naming the field and the violated constraint.
  void Check() const;
};

/// An opaque shape in front of the board, given in image pixels (distorted image, pixel
/// centres at integer coordinates): it hides whatever lies behind it, is anti-aliased at its
/// rim, and is lit like the scene (gradient, gain and offset apply to it too).
struct Occluder {
  enum class Shape { kRectangle, kDisc };
  Shape shape = Shape::kRectangle;
  double centre_u_px = 0.0;     ///< centre column, pixels, finite (may lie outside the image)
  double centre_v_px = 0.0;     ///< centre row, pixels, finite
  double half_width_px = 0.0;   ///< rectangle: half extent along u; disc: radius; pixels, > 0
  double half_height_px = 0.0;  ///< rectangle: half extent along v, pixels, > 0; disc: unused
  int grey = 128;               ///< uniform grey level, [0, 255]

  /// True when the point (u, v) (pixels) lies inside the shape.
  bool Contains(double u, double v) const;
  /// Throws std::invalid_argument naming the field and the violated constraint.
  void Check() const;
};

/// Something lying on the target's plane or held just above it, in front of the board and the
/// surface: a hand, a pen, a cable, a tool. Its outline is a union of capsules (a segment with
/// a radius) and ellipses on the plane (object frame, metres); it is anti-aliased from its
/// distance to the rim, textured, and may cast a soft shadow on what lies under it.
struct PlaneOccluder {
  struct Capsule {
    double x1_m = 0.0, y1_m = 0.0, x2_m = 0.0, y2_m = 0.0;  ///< the segment, finite
    double radius_m = 0.01;                                 ///< (0, 1]
  };
  struct Ellipse {
    double x_m = 0.0, y_m = 0.0;              ///< centre, finite
    double semi_a_m = 0.05, semi_b_m = 0.03;  ///< semi-axes along angle_rad and across, (0, 1]
    double angle_rad = 0.0;                   ///< finite
  };
  std::vector<Capsule> capsules;
  std::vector<Ellipse> ellipses;
  std::string label;  ///< what it is ("hand", "pen"...), for the truth files; may be empty
  int grey = 150;     ///< its mean grey level, [0, 255]
  /// Its grey varies smoothly by up to +-texture_grey (value noise on 5 mm cells from
  /// texture_seed: skin, fabric, a printed pen). [0, 100]
  double texture_grey = 0.0;
  std::uint64_t texture_seed = 0;
  /// Held above the plane, it shades what lies under it: the outline moved by shadow_offset_m
  /// along shadow_angle_rad (object frame), its edge ramping over shadow_softness_m, darkens by
  /// the factor 1 - shadow_darkness. 0: none. [0, 0.95]
  double shadow_darkness = 0.0;
  double shadow_offset_m = 0.0;     ///< [0, 1]
  double shadow_angle_rad = 0.0;    ///< finite
  double shadow_softness_m = 0.01;  ///< [0, 1]

  /// The signed distance from the plane point (X, Y) to the outline, metres: negative inside.
  /// Exact for the capsules, first order near the rim for the ellipses.
  double SignedDistance(double X, double Y) const;
  bool Contains(double X, double Y) const { return SignedDistance(X, Y) <= 0.0; }
  /// Throws std::invalid_argument naming the field and the violated constraint.
  void Check() const;
};

/// A lamp's reflection on the paper: grey levels added around a point of the target's plane
/// with a Gaussian fall-off, before the exposure, so that its core saturates the sensor over
/// ink and paper alike.
struct Glare {
  double x_m = 0.0, y_m = 0.0;  ///< centre on the plane (object frame), finite
  double sigma_m = 0.02;        ///< the Gaussian's standard deviation on the plane, (0, 1]
  double peak_grey = 300.0;     ///< added at the centre, grey levels, [0, 2000]

  /// Throws std::invalid_argument naming the field and the violated constraint.
  void Check() const;
};

/// What changes from one frame of a sequence to the next besides the pose: a global
/// illumination change and occluders. The default is a frame rendered as by Render(cMo, seed).
struct FrameEffects {
  /// Scene radiance (after the illumination gradient) is mapped to gain * radiance + offset.
  double gain = 1.0;                ///< [0, 10]
  double offset = 0.0;              ///< grey levels, [-255, 255]
  std::vector<Occluder> occluders;  ///< drawn in order, the last one in front
  /// This frame's noise and blur instead of RenderOptions' (a camera whose exposure or focus
  /// varies); negative: RenderOptions'. Ranges as RenderOptions'.
  double noise_sigma = -1.0;
  double blur_sigma_px = -1.0;
  /// Things on or over the target's plane, drawn in order after the scene and its glares.
  std::vector<PlaneOccluder> plane_occluders;
  std::vector<Glare> glares;
  /// The camera moved during the exposure: the image integrated along a straight path of
  /// this length in pixels, in the direction motion_blur_angle_rad from the image's u axis
  /// towards v (applied after the gain, before the blur and the noise). 0: none. [0, 200]
  double motion_blur_px = 0.0;
  double motion_blur_angle_rad = 0.0;  ///< finite
  /// The frame as a webcam's MJPEG delivers it: compressed as a JPEG of this quality and
  /// decoded, last. 0: not compressed. [0, 100]
  int jpeg_quality = 0;

  /// Throws std::invalid_argument naming the field and the violated constraint.
  void Check() const;
};

/// Ground truth of one target line in one frame (pixel conventions of detector/line.h).
struct TruthLine {
  int index = 0;             ///< 0-based index in LineTarget::lines
  bool visible = false;      ///< some of its centre line is inside the image
  LineParams ideal;          ///< projection of the centre line, undistorted pixels (always set
                             ///< unless the line passes through the centre of projection)
  LineParams distorted_fit;  ///< total-least-squares line through its distorted image, pixels
  Point2d end_a, end_b;      ///< ends of its visible part in the distorted image
  double visible_length_px = 0.0;  ///< |end_b - end_a|, pixels
  double width_px = 0.0;  ///< apparent width in the middle of the visible part, ideal pixels
  /// Fraction of the visible part of the centre line hidden by occluders (in the image or on
  /// the plane), [0, 1]. Occlusion never makes a line invisible: `visible` and the fields
  /// above ignore occluders.
  double occluded_fraction = 0.0;
};

struct RenderedFrame {
  vpImage<unsigned char> image;
  vpHomogeneousMatrix cMo;
  std::vector<TruthLine> truth;
};

struct SceneDressing;  // scene.cpp

class SceneRenderer {
 public:
  /// Throws std::invalid_argument if the target or the options fail Check(). Annotations and
  /// clutter are laid out here, once.
  SceneRenderer(LineTarget target, RenderOptions options);

  /// Renders the target seen from `cMo`; `noise_seed` makes the noise reproducible.
  RenderedFrame Render(const vpHomogeneousMatrix& cMo, std::uint64_t noise_seed) const;
  /// The same with per-frame effects: the plane occluders' shadows, the glares and the plane
  /// occluders over the scene, then the image occluders, the illumination gradient, the light
  /// fall-off (vignetting, hot spot), gain and offset, motion blur, blur and noise in that
  /// order; the 8-bit frame is then compressed as a JPEG when asked. Throws
  /// std::invalid_argument if `effects` fails Check().
  RenderedFrame Render(const vpHomogeneousMatrix& cMo, std::uint64_t noise_seed,
                       const FrameEffects& effects) const;
  /// Ground truth only (no image), e.g. for a pose that is not rendered.
  std::vector<TruthLine> Truth(const vpHomogeneousMatrix& cMo) const;
  /// Ground truth with the occluded fraction of each line under `effects`.
  std::vector<TruthLine> Truth(const vpHomogeneousMatrix& cMo, const FrameEffects& effects) const;

  const LineTarget& target() const { return target_; }
  const RenderOptions& options() const { return options_; }

 private:
  LineTarget target_;
  RenderOptions options_;
  // Per-pixel ideal normalised coordinates of the distorted image (computed once).
  std::vector<float> ray_x_, ray_y_;
  std::shared_ptr<const vpImage<unsigned char>> background_;  // never null
  // Annotations and clutter laid out on the plane (scene.cpp; null when there are none).
  std::shared_ptr<const SceneDressing> dressing_;
};

/// Random camera poses looking at the target for data sets and tests.
/// The optical axis meets the board at a point drawn uniformly in a disc of radius
/// max_offset_m; the camera centre lies on the front side (object z < 0) at a distance drawn
/// uniformly in [min_distance_m, max_distance_m] from that point, measured along the axis.
struct PoseSampling {
  double min_distance_m = 0.4, max_distance_m = 0.9;  ///< 0 < min <= max
  double max_tilt_deg = 30.0;  ///< angle between optical axis and board normal, [0, 80]
  /// ... uniform from this angle to max_tilt_deg: views tilted as a calibration asks for
  /// them (30-45 degrees). [0, max_tilt_deg].
  double min_tilt_deg = 0.0;
  double max_offset_m = 0.05;  ///< where the optical axis meets the board, from its centre, >= 0
  bool any_roll = true;        ///< roll uniform in [0, 360) deg; else within +-max_tilt_deg
  /// Every target line must cross the image over at least this length (0: no check).
  double min_visible_length_px = 0.0;
  /// Every crossing square of the target (StripeCrossings) must be in view: its four corners
  /// in front of the camera and at least crossings_margin_px inside the image's border in the
  /// distorted image. With max_offset_m larger than the crossings' extent this keeps what the
  /// pose needs in view while the board is often partly out of it. A target without crossings
  /// passes.
  bool crossings_in_view = false;
  double crossings_margin_px = 10.0;  ///< pixels, [0, 1000]

  /// Throws std::invalid_argument naming the field and the violated constraint.
  void Check() const;
};

/// Where two stripes of a target cross: the parallelogram both cover.
struct StripeCrossing {
  int line_a = 0, line_b = 0;  ///< indices in LineTarget::lines, line_a < line_b
  /// Its corners (X, Y) in the board plane (object frame, metres), in order around it.
  std::array<std::array<double, 2>, 4> corners_m{};
};

/// Every crossing of `target`: each pair of non-parallel stripes (more than 1 degree apart)
/// whose centre segments intersect, in the order of (line_a, line_b). Four for a '#'.
std::vector<StripeCrossing> StripeCrossings(const LineTarget& target);

/// True when every corner of every StripeCrossings(renderer.target()) square is in front of
/// the camera at `cMo` and at least margin_px inside the image's border (distorted pixels).
bool CrossingsInView(const SceneRenderer& renderer, const vpHomogeneousMatrix& cMo,
                     double margin_px);

/// A pose drawn from `sampling` with the pseudo-random generator state `*state`
/// (deterministic: the same state gives the same pose, and *state is advanced so that calls in
/// a row give a reproducible sequence). Retries until the visibility requirements hold (at
/// most 1000 draws, then throws std::runtime_error). The requirements only reject draws, so
/// with crossings_in_view false the same state gives the same poses as before it existed.
vpHomogeneousMatrix SamplePose(const SceneRenderer& renderer, const PoseSampling& sampling,
                               std::uint64_t* state);

}  // namespace oal
