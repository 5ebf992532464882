// A camera's lens: its intrinsics and its distortion, in one of two models, and the maps
// between a distorted pixel and the ideal normalised point it sees.
//
// Only feature points are corrected, never the image (the paper's main source of failures is
// the lens, see NOTES 5): a distorted pixel (u, v) maps to the pixel (u', v') where an ideal
// pinhole camera with the same intrinsics would have seen it.
//
// Two models, each exact in its own direction:
// - ViSP's one-term model (vpCameraParameters::perspectiveProjWithDistortion): the ideal point
//   of a distorted pixel is x = (u - u0) / px (1 + kdu r^2), r the distorted normalised
//   radius; the other direction is solved (kud, ViSP's approximate inverse, is kept for ViSP's
//   own tools).
// - OpenCV's model (calib3d, ROS's plumb_bob, and its rational extension): an ideal point
//   (x, y), r^2 = x^2 + y^2, is seen at
//     x' = x (1 + k1 r^2 + k2 r^4 + k3 r^6) / (1 + k4 r^2 + k5 r^4 + k6 r^6)
//          + 2 p1 x y + p2 (r^2 + 2 x^2),
//     y' = y (...) / (...) + p1 (r^2 + 2 y^2) + 2 p2 x y,
//   u = u0 + px x', v = v0 + py y'; the other direction is solved by Newton's method.
// A lens without distortion is the pinhole special case of both. OpenCV's thin-prism and
// tilted-sensor terms and its fisheye model are not supported: webcam lenses up to ~100
// degrees across are fitted by the rational model, and the files users have (OpenCV's
// calibration YAML, ROS's camera_info) carry plumb_bob or rational_polynomial.
#pragma once

#include <visp3/core/vpCameraParameters.h>

#include <array>
#include <string>

#include "detector/line.h"

namespace oal {

/// OpenCV's distortion coefficients, in calib3d's order (k1, k2, p1, p2, k3, k4, k5, k6).
struct Distortion {
  /// The coefficients' names, in calib3d's order.
  static constexpr std::array<const char*, 8> kNames = {"k1", "k2", "p1", "p2",
                                                        "k3", "k4", "k5", "k6"};

  double k1 = 0.0, k2 = 0.0, p1 = 0.0, p2 = 0.0, k3 = 0.0, k4 = 0.0, k5 = 0.0, k6 = 0.0;

  /// In calib3d's order.
  std::array<double, 8> ToArray() const { return {k1, k2, p1, p2, k3, k4, k5, k6}; }
  static Distortion FromArray(const std::array<double, 8>& c);
  bool IsZero() const;
  /// True when any of k4, k5, k6 is set (OpenCV's CALIB_RATIONAL_MODEL, ROS's
  /// rational_polynomial).
  bool IsRational() const { return k4 != 0.0 || k5 != 0.0 || k6 != 0.0; }
  bool operator==(const Distortion& other) const { return ToArray() == other.ToArray(); }
};

class Lens {
 public:
  enum class Model { kPinhole, kViSP, kOpenCV };

  /// ViSP's default camera (vpCameraParameters()).
  Lens();
  /// ViSP's camera, its one-term model when it has distortion. Implicit: a ViSP camera is a
  /// lens wherever one is asked for.
  Lens(const vpCameraParameters& camera);  // NOLINT(google-explicit-constructor)

  static Lens Pinhole(double px, double py, double u0, double v0);
  /// ViSP's one-term model with `kdu`, and the kud that best inverts it over a width x height
  /// image (least squares), as a calibration gives both (kud = 0 when kdu = 0).
  static Lens WithKdu(double px, double py, double u0, double v0, double kdu, int width,
                      int height);
  /// ViSP's one-term model with both coefficients given (a camera file's).
  static Lens WithKudKdu(double px, double py, double u0, double v0, double kud, double kdu);
  /// OpenCV's model; the pinhole when every coefficient is zero.
  static Lens WithDistortion(double px, double py, double u0, double v0,
                             const Distortion& distortion);

  Model model() const { return model_; }
  bool distorted() const { return model_ != Model::kPinhole; }
  double px() const { return px_; }
  double py() const { return py_; }
  double u0() const { return u0_; }
  double v0() const { return v0_; }
  /// ViSP's model's coefficients; 0 in the other models.
  double kdu() const { return kdu_; }
  double kud() const { return kud_; }
  /// OpenCV's coefficients; all zero in the other models.
  const Distortion& distortion() const { return distortion_; }

  /// The ideal normalised point (x, y) seen at the distorted pixel (u, v); NaN where the
  /// model reaches no ideal point (OpenCV's model beyond the radius where it folds over).
  Point2d Normalised(double u, double v) const;
  /// The distorted pixel of the ideal normalised point (x, y), to 1e-9 px; NaN where the
  /// model cannot reach it (ViSP's with kdu < 0 beyond its largest radius, OpenCV's beyond
  /// the radius where its radial map turns back).
  Point2d Pixel(double x, double y) const;

  /// The same distortion with other intrinsics (an image scaled or shifted).
  Lens WithIntrinsics(double px, double py, double u0, double v0) const {
    Lens lens = *this;
    lens.px_ = px;
    lens.py_ = py;
    lens.u0_ = u0;
    lens.v0_ = v0;
    return lens;
  }

  /// d(x, y)/d(u, v) of Normalised() at the distorted pixel (u, v) whose ideal point is
  /// `ideal`, as {dx/du, dx/dv, dy/du, dy/dv} (a pixel's footprint on the rays).
  std::array<double, 4> NormalisedDerivative(double u, double v, const Point2d& ideal) const;

  /// ViSP's camera of the same intrinsics without distortion (for ViSP's tools that work on
  /// ideal pixels or normalised points).
  vpCameraParameters PinholeCamera() const;
  /// ViSP's camera of this lens: exact for the pinhole and ViSP's model; for OpenCV's model,
  /// the one-term kdu that best maps the width x height image's pixels to their ideal points
  /// (least squares), with its kud (`IsViSPApproximation` tells which).
  vpCameraParameters ViSPCamera(int width, int height) const;
  /// True when ViSPCamera() is only an approximation of this lens.
  bool IsViSPApproximation() const { return model_ == Model::kOpenCV; }
  /// OpenCV's model of this lens: itself for the pinhole and OpenCV's model; for ViSP's, the
  /// coefficients (k1, k2, 0, 0, k3) that best map the width x height image's pixels to their
  /// ideal points (least squares), what calibrating it with OpenCV's default model gives.
  Lens OpenCvCamera(int width, int height) const;
  /// True when OpenCvCamera() is only an approximation of this lens.
  bool IsOpenCvApproximation() const { return model_ == Model::kViSP; }

  /// OpenCV's model: the largest ideal normalised radius squared the model maps outwards
  /// (where its radial map turns back), infinity if none within 87 degrees off axis.
  double max_ideal_r2() const { return max_ideal_r2_; }

  bool operator==(const Lens& other) const;
  bool operator!=(const Lens& other) const { return !(*this == other); }

 private:
  Model model_ = Model::kPinhole;
  double px_ = 0.0, py_ = 0.0, u0_ = 0.0, v0_ = 0.0;
  double kud_ = 0.0, kdu_ = 0.0;
  Distortion distortion_;
  double max_ideal_r2_ = 0.0;  ///< OpenCV's model: the ideal radius^2 where it folds over

  static double FoldRadius2(const Distortion& distortion);
  Point2d SolveFrom(double xd, double yd, const Point2d& guess) const;
};

/// Maps distorted feature pixels to ideal pixels of `lens` (same intrinsics, no distortion);
/// ViSP's model in closed form, OpenCV's by Newton's method.
class PointUndistorter {
 public:
  explicit PointUndistorter(const Lens& lens);

  /// True when the lens has distortion to correct.
  bool active() const { return lens_.distorted(); }
  Point2d Undistort(const Point2d& pixel) const {
    if (lens_.model() == Lens::Model::kViSP) {
      const double du = pixel.u - lens_.u0(), dv = pixel.v - lens_.v0();
      const double factor = 1.0 + lens_.kdu() * (du * du * inv_px2_ + dv * dv * inv_py2_);
      return Point2d{lens_.u0() + du * factor, lens_.v0() + dv * factor};
    }
    if (lens_.model() == Lens::Model::kPinhole) return pixel;
    const Point2d x = lens_.Normalised(pixel.u, pixel.v);
    return Point2d{lens_.u0() + lens_.px() * x.u, lens_.v0() + lens_.py() * x.v};
  }
  /// A short vector at the distorted `pixel` (whose Undistort is `ideal`), as the undistortion
  /// maps it: a run across a stripe in ideal pixels. Near the corners of a wide lens a run is
  /// a third shorter in the image than on the ideal one.
  Point2d UndistortVector(const Point2d& pixel, const Point2d& ideal, const Point2d& vector) const {
    if (lens_.model() == Lens::Model::kPinhole) return vector;
    const Point2d x{(ideal.u - lens_.u0()) / lens_.px(), (ideal.v - lens_.v0()) / lens_.py()};
    const auto [xu, xv, yu, yv] = lens_.NormalisedDerivative(pixel.u, pixel.v, x);
    return Point2d{lens_.px() * (xu * vector.u + xv * vector.v),
                   lens_.py() * (yu * vector.u + yv * vector.v)};
  }

 private:
  Lens lens_;
  double inv_px2_, inv_py2_;
};

/// The model's name as ViSP's camera files and ROS's camera_info give it:
/// "perspectiveProjWithoutDistortion", "perspectiveProjWithDistortion" (ViSP's one-term
/// model), "plumb_bob" (OpenCV's five coefficients) or "rational_polynomial" (its eight).
std::string LensModelName(const Lens& lens);

/// The distorted over the ideal normalised radius of a point whose ideal radius squared is
/// `rho2`, under ViSP's kdu model (ideal rho = r (1 + kdu r^2) of distorted r), to rounding;
/// NaN where kdu < 0 reaches no such radius.
double DistortedOverIdeal(double kdu, double rho2);

/// The kud that best inverts the lens's kdu over a width x height image (least squares), so a
/// camera file written with both is consistent in ViSP's two directions.
double FitKud(const Lens& lens, int width, int height);

/// The largest distance between the ideal pixels (u0 + px x, v0 + py y) two lenses give the
/// same distorted pixel, over a grid of a width x height image (how far an approximation
/// misses), within `max_radius_px` of a's principal point; infinity where one has no ideal
/// point.
double WorstIdealPixelDifference(const Lens& a, const Lens& b, int width, int height,
                                 double max_radius_px = 1e300);

/// The largest distorted normalised radius squared of a width x height image's corners.
double CornerRadius2(const Lens& lens, int width, int height);

/// Throws std::invalid_argument naming `field` (e.g. "PoseOptions::camera") unless `lens`
/// has finite px, py > 0, finite u0, v0 and finite coefficients.
void CheckPerspectiveCamera(const Lens& lens, const std::string& field);

/// Throws std::invalid_argument naming `field` unless every pixel of a width x height image
/// maps to an ideal point and back (the model does not fold over inside the image).
void CheckInvertibleOver(const Lens& lens, int width, int height, const std::string& field);

}  // namespace oal
