#include "servo/stripe_fit.h"

#include <visp3/core/vpThetaUVector.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "base/check.h"
#include "base/pose_distance.h"
#include "base/statistics.h"
#include "detector/lens.h"

namespace oal {
namespace {

// Tukey's biweight constant (95 % efficiency for Gaussian residuals), and the cut of the
// points counted as kept, in robust scales.
constexpr double kTukey = 4.685;
constexpr double kKeptScales = 2.5;
// A stripe's extent counts the stretches of its kept points that hold this many points at
// least, each within this fraction of the stripe's length of the next: one or two points far
// from the rest (runs cut by a hand's edge, a speck) would tell the stripe's angle alone.
constexpr std::size_t kMinStretchPoints = 3;
constexpr double kMaxStretchGap = 0.05;
// Points this close to a crossing's stripe (beyond its half width), metres, are left out: a
// run there may have merged with the crossing stripe.
constexpr double kCrossingMarginM = 0.002;
// Two fits' poses this close (radians, and metres over the depth) are one.
constexpr double kSameFitRad = 2e-3;
// A step smaller than this (radians, and metres over the target's distance) has converged.
constexpr double kConverged = 1e-7;
// A guided point may lie this fraction of its stripe's length beyond its ends as the starting
// pose puts them (the start may be a few percent off in scale).
constexpr double kGuideSpanMargin = 0.1;
// A stripe's points all this close to their own straight line, pixels, need no sorting out;
// farther, the line most of them lie on decides which are the stripe's (something dark lying
// along the stripe lines up a run of points a pixel or two off it).
constexpr double kCollinearPx = 1.0;
// ... the points kept then: within this many of the line's robust scales, or half a pixel.
constexpr double kCollinearScales = 3.0;
constexpr double kCollinearMinPx = 0.5;
// At most this many of a stripe's points (evenly along it) propose the candidate lines.
constexpr std::size_t kCollinearProposers = 16;

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Mat36 = Eigen::Matrix<double, 3, 6>;
using Row6 = Eigen::Matrix<double, 1, 6>;
using Vec6 = Eigen::Matrix<double, 6, 1>;

// A pose as a rotation and a translation (cMo: X_c = R X_o + t).
struct Pose {
  Mat3 r;
  Vec3 t;

  static Pose Of(const vpHomogeneousMatrix& cMo) {
    Pose pose;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) pose.r(i, j) = cMo[i][j];
      pose.t(i) = cMo[i][3];
    }
    return pose;
  }
  vpHomogeneousMatrix Matrix() const {
    vpHomogeneousMatrix cMo;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) cMo[i][j] = r(i, j);
      cMo[i][3] = t(i);
    }
    return cMo;
  }
  Vec3 Of(const Point2d& plane) const { return r.col(0) * plane.u + r.col(1) * plane.v + t; }
  // Moved by the camera-frame motion (v, w): R' = exp(w) R, t' = exp(w) t + v.
  void Move(const Vec6& step) {
    const Vec3 w = step.tail<3>();
    const double angle = w.norm();
    const Mat3 turn =
        angle > 0.0 ? Eigen::AngleAxisd(angle, w / angle).toRotationMatrix() : Mat3::Identity();
    r = turn * r;
    t = turn * t + step.head<3>();
  }
};

// The image line (homogeneous, normalised coordinates) through the images of two camera-frame
// points, and its derivative under the camera-frame motion (v, w): X' = X + v + w x X.
struct ImageLine {
  Vec3 n;
  Mat36 d;
};
Mat36 MotionDerivative(const Vec3& x) {
  Mat36 d;
  d.leftCols<3>().setIdentity();
  d.rightCols<3>() << 0.0, x(2), -x(1), -x(2), 0.0, x(0), x(1), -x(0), 0.0;
  return d;
}
ImageLine Through(const Vec3& a, const Vec3& b) {
  const Mat36 da = MotionDerivative(a), db = MotionDerivative(b);
  ImageLine line;
  line.n = a.cross(b);
  for (int j = 0; j < 6; ++j) {
    line.d.col(j) = Vec3(da.col(j)).cross(b) + a.cross(Vec3(db.col(j)));
  }
  return line;
}

// A stripe's points, in normalised coordinates, their runs' middles moved onto the centre
// line's locus, and their place along the stripe ('#' coordinate).
struct StripePoints {
  std::vector<Vec3> p;
  std::vector<double> along;
  std::vector<double> run_width;  // the run's width across the stripe, pixels
  std::vector<double> width;      // the stripe's width across there, pixels

  void Add(const Vec3& point, double at, double measured_px, double predicted_px) {
    p.push_back(point);
    along.push_back(at);
    run_width.push_back(measured_px);
    width.push_back(predicted_px);
  }
};

// A line through pixel points: unit normal (nu, nv) and offset, nu u + nv v = c.
struct PixelLine {
  double nu = 0.0, nv = 1.0, c = 0.0;
  double Distance(double u, double v) const { return std::fabs(nu * u + nv * v - c); }
};

// The total-least-squares line through the points `p` (normalised) in pixels (px, py).
PixelLine FitLine(const std::vector<Vec3>& p, double px, double py) {
  double mu = 0.0, mv = 0.0;
  for (const Vec3& q : p) {
    mu += q(0) * px;
    mv += q(1) * py;
  }
  mu /= static_cast<double>(p.size());
  mv /= static_cast<double>(p.size());
  double suu = 0.0, suv = 0.0, svv = 0.0;
  for (const Vec3& q : p) {
    const double du = q(0) * px - mu, dv = q(1) * py - mv;
    suu += du * du;
    suv += du * dv;
    svv += dv * dv;
  }
  // The normal is the direction of least spread.
  const double along = 0.5 * std::atan2(2.0 * suv, suu - svv);
  PixelLine line{-std::sin(along), std::cos(along), 0.0};
  line.c = line.nu * mu + line.nv * mv;
  return line;
}

// Keeps the stripe's points on the line most of them lie on (least median of distances over
// the lines through pairs of them), when they are not all close to one line.
void KeepCollinear(double px, double py, StripePoints* stripe) {
  const std::size_t n = stripe->p.size();
  if (n < 4) return;
  const PixelLine least_squares = FitLine(stripe->p, px, py);
  double worst = 0.0;
  for (const Vec3& q : stripe->p)
    worst = std::max(worst, least_squares.Distance(q(0) * px, q(1) * py));
  if (worst <= kCollinearPx) return;

  std::vector<double> u(n), v(n);
  std::vector<std::size_t> all(n);
  for (std::size_t i = 0; i < n; ++i) {
    u[i] = stripe->p[i](0) * px;
    v[i] = stripe->p[i](1) * py;
    all[i] = i;
  }
  std::sort(all.begin(), all.end(),
            [&](std::size_t a, std::size_t b) { return stripe->along[a] < stripe->along[b]; });
  const std::size_t proposers = std::min(n, kCollinearProposers);
  std::vector<double> distances(n);
  PixelLine best;
  double best_median = HUGE_VAL;
  for (std::size_t a = 0; a < proposers; ++a) {
    for (std::size_t b = a + 1; b < proposers; ++b) {
      const std::size_t i = all[a * (n - 1) / (proposers - 1)];
      const std::size_t j = all[b * (n - 1) / (proposers - 1)];
      const double du = u[j] - u[i], dv = v[j] - v[i], length = std::hypot(du, dv);
      if (!(length > 0.0)) continue;
      PixelLine line{-dv / length, du / length, 0.0};
      line.c = line.nu * u[i] + line.nv * v[i];
      for (std::size_t k = 0; k < n; ++k) distances[k] = line.Distance(u[k], v[k]);
      const double median = MedianInPlace(&distances);
      if (median < best_median) {
        best_median = median;
        best = line;
      }
    }
  }
  if (!(best_median < HUGE_VAL)) return;
  const double keep = std::max(kCollinearMinPx, kCollinearScales * 1.4826 * best_median);
  StripePoints kept;
  for (std::size_t i = 0; i < n; ++i) {
    if (best.Distance(u[i], v[i]) > keep) continue;
    kept.Add(stripe->p[i], stripe->along[i], stripe->run_width[i], stripe->width[i]);
  }
  *stripe = std::move(kept);
}

class Fitter {
 public:
  Fitter(const TargetLayout& layout, const Lens& camera, const StripeFitOptions& options)
      : layout_(layout), camera_(camera), options_(options) {
    const double det = layout.axis_a.u * layout.axis_b.v - layout.axis_a.v * layout.axis_b.u;
    inverse_ = {layout.axis_b.v / det, -layout.axis_b.u / det, -layout.axis_a.v / det,
                layout.axis_a.u / det};
    inv_px2_ = 1.0 / (camera.px() * camera.px());
    inv_py2_ = 1.0 / (camera.py() * camera.py());
    focal_ = std::sqrt(camera.px() * camera.py());
  }

  // Sorts `points` onto the stripes where `pose` puts them.
  void Assign(const Pose& pose, const std::vector<FramePoint>& points, bool undistorted,
              const StripeGuides* guides, const RunWidthBand* band,
              std::array<StripePoints, 4>* stripes) const {
    Mat3 homography;
    homography << pose.r.col(0), pose.r.col(1), pose.t;
    const Mat3 image_to_plane = homography.inverse();
    std::array<StripeSight, 4> sights;
    for (int k = 0; k < 4; ++k) {
      StripePoints& s = (*stripes)[static_cast<std::size_t>(k)];
      s.p.clear();
      s.along.clear();
      s.run_width.clear();
      s.width.clear();
      s.p.reserve(points.size());
      s.along.reserve(points.size());
      s.run_width.reserve(points.size());
      s.width.reserve(points.size());
      sights[static_cast<std::size_t>(k)] = SightOf(pose, k);
    }
    for (const FramePoint& source : points) {
      if (!source.straight || (source.across_u == 0.0f && source.across_v == 0.0f) ||
          !(source.background_step <= options_.max_background_step)) {
        continue;
      }
      Vec3 p(0.0, 0.0, 1.0);
      if (undistorted) {
        p(0) = (source.p.u - camera_.u0()) / camera_.px();
        p(1) = (source.p.v - camera_.v0()) / camera_.py();
      } else {
        const Point2d ideal = camera_.Normalised(source.p.u, source.p.v);
        p(0) = ideal.u;
        p(1) = ideal.v;
      }
      const Vec3 q = image_to_plane * p;
      if (!(q(2) > 0.0)) continue;
      const double X = q(0) / q(2) - layout_.origin.u, Y = q(1) / q(2) - layout_.origin.v;
      const double a = inverse_[0] * X + inverse_[1] * Y, b = inverse_[2] * X + inverse_[3] * Y;
      // The corridor on the plane, generously: a pixel is depth / f metres face on, more when
      // the plane is seen at a slant (the residual below decides in pixels).
      const double corridor_m = 4.0 * options_.corridor_px / (q(2) * focal_);
      // On a guide line: the stripe's, wherever the pose puts it (off the crossings and a
      // little beyond its ends at most, as the pose places them).
      if (guides != nullptr) {
        int guided = -1;
        for (int k = 0; k < 4 && guided < 0; ++k) {
          const std::optional<LineParams>& guide = (*guides)[static_cast<std::size_t>(k)];
          if (!guide || !(std::fabs(guide->SignedDistance(source.p.u, source.p.v)) <=
                          options_.guide_tolerance_px)) {
            continue;
          }
          const StripeSpan& span = layout_.stripes[static_cast<std::size_t>(k)];
          const double along = span.along_b ? b : a;
          const double margin = kGuideSpanMargin * (span.along.hi - span.along.lo);
          if (along < span.along.lo - margin || along > span.along.hi + margin ||
              NearCrossing(span, along)) {
            continue;
          }
          guided = k;
          const StripeSight& sight = sights[static_cast<std::size_t>(k)];
          Vec3 shifted;
          double measured = 0.0, predicted = 0.0;
          OnLocus(source, p, sight, &shifted);
          if (!WidthAgrees(sight, along, source, &measured, &predicted) ||
              !InBand(band, k, measured - predicted)) {
            continue;
          }
          (*stripes)[static_cast<std::size_t>(k)].Add(shifted, along, measured, predicted);
        }
        if (guided >= 0) continue;
      }
      for (int k = 0; k < 4; ++k) {
        if (guides != nullptr && (*guides)[static_cast<std::size_t>(k)]) continue;
        const StripeSpan& span = layout_.stripes[static_cast<std::size_t>(k)];
        const double along = span.along_b ? b : a, across = (span.along_b ? a : b) - span.at;
        if (std::fabs(across) > span.half + corridor_m || along < span.along.lo ||
            along > span.along.hi || NearCrossing(span, along)) {
          continue;
        }
        const StripeSight& sight = sights[static_cast<std::size_t>(k)];
        Vec3 shifted;
        double measured = 0.0, predicted = 0.0;
        if (!OnLocus(source, p, sight, &shifted) ||
            !WidthAgrees(sight, along, source, &measured, &predicted)) {
          continue;
        }
        // Off the band's width: not taken, and not another stripe's either.
        if (!InBand(band, k, measured - predicted)) break;
        (*stripes)[static_cast<std::size_t>(k)].Add(shifted, along, measured, predicted);
        break;  // the stripes lie apart: a run is on one of them at most
      }
    }
  }

  // The pixel length of the image line n's unit normal in normalised coordinates.
  double Scale(const Vec3& n) const {
    return std::sqrt(n(0) * n(0) * inv_px2_ + n(1) * n(1) * inv_py2_);
  }

  double inv_px2() const { return inv_px2_; }
  double inv_py2() const { return inv_py2_; }

 private:
  // A stripe as a pose shows it: its centre line and edges (normalised), the centre line's
  // unit normal in pixels, and its width across in pixels at its ends and middle.
  struct StripeSight {
    Vec3 centre, low, high;
    double nu = 0.0, nv = 0.0;
    double lo = 0.0, hi = 0.0;  // the span's ends ('#' coordinate)
    std::array<double, 3> width{};
  };

  StripeSight SightOf(const Pose& pose, int k) const {
    const StripeSpan& span = layout_.stripes[static_cast<std::size_t>(k)];
    StripeSight sight;
    const auto line = [&](double across) {
      return pose.Of(layout_.OnStripe(k, span.along.lo, across))
          .cross(pose.Of(layout_.OnStripe(k, span.along.hi, across)));
    };
    sight.centre = line(0.0);
    sight.low = line(-span.half);
    sight.high = line(span.half);
    const double nu = sight.centre(0) / camera_.px(), nv = sight.centre(1) / camera_.py();
    const double norm = std::sqrt(nu * nu + nv * nv);
    sight.nu = nu / norm;
    sight.nv = nv / norm;
    sight.lo = span.along.lo;
    sight.hi = span.along.hi;
    for (int i = 0; i < 3; ++i) {
      const double along = span.along.lo + 0.5 * i * (span.along.hi - span.along.lo);
      const Vec3 lo = pose.Of(layout_.OnStripe(k, along, -span.half));
      const Vec3 hi = pose.Of(layout_.OnStripe(k, along, span.half));
      // Behind the camera: no width (a run there is never the stripe's).
      sight.width[static_cast<std::size_t>(i)] =
          lo(2) > 0.0 && hi(2) > 0.0
              ? std::fabs(camera_.px() * (hi(0) / hi(2) - lo(0) / lo(2)) * sight.nu +
                          camera_.py() * (hi(1) / hi(2) - lo(1) / lo(2)) * sight.nv)
              : 0.0;
    }
    return sight;
  }

  bool NearCrossing(const StripeSpan& span, double along) const {
    for (const StripeSpan& other : layout_.stripes) {
      if (other.along_b != span.along_b &&
          std::fabs(along - other.at) < other.half + kCrossingMarginM) {
        return true;
      }
    }
    return false;
  }

  // The run's middle p moved along its run onto the centre line's locus (under perspective the
  // middle between converging edges is off the centre line's image), when within the corridor.
  bool OnLocus(const FramePoint& source, const Vec3& p, const StripeSight& sight,
               Vec3* shifted) const {
    const double length = std::sqrt(static_cast<double>(source.across_u) * source.across_u +
                                    static_cast<double>(source.across_v) * source.across_v);
    const double du = source.across_u / length / camera_.px();
    const double dv = source.across_v / length / camera_.py();
    const auto along = [&](const Vec3& line) {
      const double towards = line(0) * du + line(1) * dv;
      return std::fabs(towards) > 1e-15 ? -line.dot(p) / towards : 0.0;
    };
    *shifted = p;
    const double shift = along(sight.centre) - 0.5 * (along(sight.low) + along(sight.high));
    if (std::fabs(shift) < 1.0) {  // pixels; larger: a pose too far off to say
      (*shifted)(0) += shift * du;
      (*shifted)(1) += shift * dv;
    }
    return std::fabs(sight.centre.dot(*shifted)) <= options_.corridor_px * Scale(sight.centre);
  }

  // Whether the run is about as wide across the stripe as the stripe is there (its width
  // interpolated between its ends and middle: it changes slowly along the stripe).
  bool WidthAgrees(const StripeSight& sight, double along, const FramePoint& source,
                   double* measured_px, double* predicted_px) const {
    const double t = 2.0 * (along - sight.lo) / (sight.hi - sight.lo) - 1.0;  // [-1, 1]
    const std::array<double, 3>& w = sight.width;
    if (!(w[0] > 0.0 && w[1] > 0.0 && w[2] > 0.0)) return false;
    const double predicted =
        w[1] + 0.5 * t * (w[2] - w[0]) + 0.5 * t * t * (w[0] + w[2] - 2.0 * w[1]);
    const double measured = WidthAcross(source, sight.nu, sight.nv);
    *measured_px = measured;
    *predicted_px = predicted;
    return measured > 0.0 && predicted > 0.0 &&
           std::max(measured, predicted) <=
               options_.max_width_ratio * std::min(measured, predicted);
  }

  static bool InBand(const RunWidthBand* band, int k, double excess) {
    return band == nullptr || band->line != k ||
           (excess >= band->min_excess_px && excess <= band->max_excess_px);
  }

  const TargetLayout& layout_;
  const Lens& camera_;
  const StripeFitOptions& options_;
  std::array<double, 4> inverse_{};
  double inv_px2_ = 1.0, inv_py2_ = 1.0, focal_ = 1.0;
};

}  // namespace

void StripeFitOptions::Check() const {
  RequireOption(corridor_px > 0.0 && corridor_px <= 1000.0, "StripeFitOptions::corridor_px",
                corridor_px, "0 < corridor_px <= 1000");
  RequireOption(min_scale_px > 0.0 && min_scale_px <= 100.0, "StripeFitOptions::min_scale_px",
                min_scale_px, "0 < min_scale_px <= 100");
  RequireOption(max_width_ratio >= 1.0 && max_width_ratio <= 100.0,
                "StripeFitOptions::max_width_ratio", max_width_ratio,
                "1 <= max_width_ratio <= 100");
  RequireOption(max_background_step > 0.0 && max_background_step <= 1e9,
                "StripeFitOptions::max_background_step", max_background_step,
                "0 < max_background_step <= 1e9");
  RequireOption(max_iterations >= 1 && max_iterations <= 100, "StripeFitOptions::max_iterations",
                max_iterations, "1 <= max_iterations <= 100");
  RequireOption(min_points >= 2 && min_points <= 1000, "StripeFitOptions::min_points", min_points,
                "2 <= min_points <= 1000");
  RequireOption(guide_tolerance_px > 0.0 && guide_tolerance_px <= 100.0,
                "StripeFitOptions::guide_tolerance_px", guide_tolerance_px,
                "0 < guide_tolerance_px <= 100");
}

vpHomogeneousMatrix MirroredTilt(const vpHomogeneousMatrix& cMo) {
  const Pose pose = Pose::Of(cMo);
  const double distance = pose.t.norm();
  if (!(distance > 0.0)) return cMo;
  const Vec3 sight = pose.t / distance;
  const Vec3 normal = pose.r.col(2);
  // The normal reflected about the line of sight, and the least turn taking one to the other.
  const Vec3 mirrored = 2.0 * normal.dot(sight) * sight - normal;
  const Vec3 axis = normal.cross(mirrored);
  const double sine = axis.norm();
  if (sine < 1e-9) return cMo;
  const double angle = std::atan2(sine, normal.dot(mirrored));
  Pose turned = pose;
  turned.r = Eigen::AngleAxisd(angle, axis / sine).toRotationMatrix() * pose.r;
  return turned.Matrix();
}

double SupportedExtent(std::vector<double>* along, double length) {
  std::sort(along->begin(), along->end());
  const double max_gap = kMaxStretchGap * length;
  double lo = HUGE_VAL, hi = -HUGE_VAL;
  for (std::size_t first = 0; first < along->size();) {
    std::size_t last = first;
    while (last + 1 < along->size() && (*along)[last + 1] - (*along)[last] <= max_gap) ++last;
    if (last - first + 1 >= kMinStretchPoints) {
      lo = std::min(lo, (*along)[first]);
      hi = std::max(hi, (*along)[last]);
    }
    first = last + 1;
  }
  return hi > lo ? std::min(1.0, (hi - lo) / length) : 0.0;
}

bool SameFitPose(const vpHomogeneousMatrix& a, const vpHomogeneousMatrix& b) {
  const PoseDistance d = Distance(a, b);
  const double depth = std::max(std::fabs(b[2][3]), 1e-3);
  return d.rotation_rad < kSameFitRad && d.translation_m < kSameFitRad * depth;
}

namespace {

// The covariance of the pose's rotation (the motion's w, radians squared): the motion (v, w) has
// scale^2 times the inverse of the weighted normal matrix, its w block the rotation's with the
// translation free to follow. Not finite when the normal matrix is singular.
Mat3 RotationCovariance(const std::array<double, 36>& normal, double scale_px) {
  const Eigen::Matrix<double, 6, 6> matrix =
      Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>>(normal.data());
  const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> solver(matrix);
  if (solver.info() != Eigen::Success) return Mat3::Constant(HUGE_VAL);
  const Eigen::Matrix<double, 6, 6> inverse = solver.solve(Eigen::Matrix<double, 6, 6>::Identity());
  return scale_px * scale_px * inverse.bottomRightCorner<3, 3>();
}

}  // namespace

double StripeFit::RotationDeviation() const {
  const Mat3 covariance = RotationCovariance(normal, scale_px);
  if (!covariance.allFinite()) return HUGE_VAL;
  const Eigen::SelfAdjointEigenSolver<Mat3> axes(covariance, Eigen::EigenvaluesOnly);
  return std::sqrt(std::max(axes.eigenvalues().maxCoeff(), 0.0));
}

double StripeFit::RotationDistance(const vpHomogeneousMatrix& other_cMo) const {
  const Mat3 covariance = RotationCovariance(normal, scale_px);
  if (!covariance.allFinite()) return 0.0;
  const Eigen::LDLT<Mat3> solver(covariance);
  if (solver.info() != Eigen::Success) return 0.0;
  const vpThetaUVector turn((other_cMo * cMo.inverse()).getRotationMatrix());
  const Vec3 w(turn[0], turn[1], turn[2]);
  return std::sqrt(std::max(w.dot(solver.solve(w)), 0.0));
}

StripeFit FitStripes(const vpHomogeneousMatrix& start, const TargetLayout& layout,
                     const std::vector<FramePoint>& points, const Lens& camera,
                     bool points_undistorted, const StripeFitOptions& options,
                     const StripeGuides* guides, int left_out_line,
                     const vpHomogeneousMatrix* known, const RunWidthBand* band) {
  options.Check();
  StripeFit fit;
  fit.cMo = start;
  const Fitter fitter(layout, camera, options);
  Pose pose = Pose::Of(start);
  // Which stripe each point is on, from the starting pose: a step moves the lines by a
  // fraction of the corridor at most, and points must not hop between stripes as it goes.
  std::array<StripePoints, 4> stripes;
  fitter.Assign(pose, points, points_undistorted, guides, band, &stripes);
  if (left_out_line >= 0 && left_out_line < 4) {
    stripes[static_cast<std::size_t>(left_out_line)] = StripePoints{};
  }
  for (StripePoints& stripe : stripes) KeepCollinear(camera.px(), camera.py(), &stripe);

  std::vector<double> magnitudes;
  double scale = options.min_scale_px;
  Eigen::Matrix<double, 6, 6> last_normal = Eigen::Matrix<double, 6, 6>::Zero();
  std::array<Vec3, 4> centre_a, centre_b;  // the centre lines' ends on the plane
  for (int k = 0; k < 4; ++k) {
    const StripeSpan& span = layout.stripes[static_cast<std::size_t>(k)];
    const Point2d a = layout.OnStripe(k, span.along.lo, 0.0);
    const Point2d b = layout.OnStripe(k, span.along.hi, 0.0);
    centre_a[static_cast<std::size_t>(k)] = Vec3(a.u, a.v, 0.0);
    centre_b[static_cast<std::size_t>(k)] = Vec3(b.u, b.v, 0.0);
  }
  std::array<ImageLine, 4> lines;
  std::array<double, 4> inv_scale{};
  const auto look = [&] {
    for (std::size_t k = 0; k < 4; ++k) {
      const Point2d a{centre_a[k](0), centre_a[k](1)}, b{centre_b[k](0), centre_b[k](1)};
      lines[k] = Through(pose.Of(a), pose.Of(b));
      inv_scale[k] = 1.0 / fitter.Scale(lines[k].n);
    }
  };
  for (fit.iterations = 0; fit.iterations < options.max_iterations;) {
    look();
    magnitudes.clear();
    for (std::size_t k = 0; k < 4; ++k) {
      for (const Vec3& p : stripes[k].p)
        magnitudes.push_back(std::fabs(lines[k].n.dot(p)) * inv_scale[k]);
    }
    scale = std::max(options.min_scale_px, 1.4826 * MedianInPlace(&magnitudes));
    const double cut = kTukey * scale, inv_cut2 = 1.0 / (cut * cut);
    // Point i of stripe k: r = s n.p (s = 1 / |n| in pixels), and its row of the Jacobian
    // dr = s p^T (dn - n ds / s^2 ...) = s p^T M, M = dn - n g, g = (n0 dn0 / px^2 + n1 dn1 /
    // py^2) s^2: so J^T W J = s^2 M^T (sum w p p^T) M and J^T W r = s M^T (sum w r p), and a
    // point costs a 3 x 3 sum.
    Eigen::Matrix<double, 6, 6> normal = Eigen::Matrix<double, 6, 6>::Zero();
    Vec6 gradient = Vec6::Zero();
    for (std::size_t k = 0; k < 4; ++k) {
      const ImageLine& line = lines[k];
      const double s = inv_scale[k];
      double xx = 0.0, xy = 0.0, x1 = 0.0, yy = 0.0, y1 = 0.0, w1 = 0.0;
      Vec3 weighted_r = Vec3::Zero();
      for (const Vec3& p : stripes[k].p) {
        const double r = line.n.dot(p) * s;
        const double r2 = r * r * inv_cut2;
        if (!(r2 < 1.0)) continue;
        const double w = (1.0 - r2) * (1.0 - r2);
        const double wx = w * p(0), wy = w * p(1);
        xx += wx * p(0);
        xy += wx * p(1);
        x1 += wx;
        yy += wy * p(1);
        y1 += wy;
        w1 += w;
        weighted_r += (w * r) * p;
      }
      if (w1 <= 0.0) continue;
      Mat3 sum;
      sum << xx, xy, x1, xy, yy, y1, x1, y1, w1;
      const Row6 g = (line.n(0) * fitter.inv_px2() * line.d.row(0) +
                      line.n(1) * fitter.inv_py2() * line.d.row(1)) *
                     (s * s);
      const Mat36 m = line.d - line.n * g;
      normal.noalias() += (s * s) * (m.transpose() * sum * m);
      gradient.noalias() += s * (m.transpose() * weighted_r);
    }
    last_normal = normal;
    const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> solver(normal);
    const Vec6 step = solver.solve(-gradient);
    if (solver.info() != Eigen::Success || !step.allFinite() ||
        !(solver.vectorD().minCoeff() > 1e-12 * solver.vectorD().maxCoeff())) {
      fit.message = "the stripes' points do not fix the pose";
      return fit;
    }
    pose.Move(step);
    ++fit.iterations;
    if (known != nullptr) {
      fit.cMo = pose.Matrix();
      if (SameFitPose(fit.cMo, *known)) {
        fit.message = "the fit came back to the known pose";
        return fit;
      }
    }
    const double depth = std::max(std::fabs(pose.t(2)), 1e-3);
    if (step.tail<3>().norm() < kConverged && step.head<3>().norm() < kConverged * depth) break;
  }

  // The points kept, their spread along each stripe, and the RMS, from the final pose.
  look();
  double sum2 = 0.0;
  int kept = 0;
  std::vector<double> along, excesses, widths;
  for (std::size_t k = 0; k < 4; ++k) {
    magnitudes.clear();  // the kept points' width ratios
    along.clear();
    excesses.clear();
    widths.clear();
    double line_sum2 = 0.0;
    for (std::size_t i = 0; i < stripes[k].p.size(); ++i) {
      const double r = lines[k].n.dot(stripes[k].p[i]) * inv_scale[k];
      if (!(std::fabs(r) <= kKeptScales * scale)) continue;
      ++fit.points[k];
      const double run_width = stripes[k].run_width[i], width = stripes[k].width[i];
      magnitudes.push_back(run_width / width);
      excesses.push_back(run_width - width);
      widths.push_back(width);
      along.push_back(stripes[k].along[i]);
      sum2 += r * r;
      line_sum2 += r * r;
      ++kept;
    }
    fit.line_rms_px[k] = fit.points[k] > 0 ? std::sqrt(line_sum2 / fit.points[k]) : 0.0;
    fit.width_ratio[k] = MedianInPlace(&magnitudes);
    fit.width_excess_px[k] = MedianInPlace(&excesses);
    fit.width_px[k] = MedianInPlace(&widths);
    const StripeSpan& span = layout.stripes[k];
    fit.extent[k] = SupportedExtent(&along, span.along.hi - span.along.lo);
  }
  fit.scale_px = scale;
  Eigen::Map<Eigen::Matrix<double, 6, 6, Eigen::RowMajor>>(fit.normal.data()) = last_normal;
  fit.rms_px = kept > 0 ? std::sqrt(sum2 / kept) : 0.0;
  fit.cMo = pose.Matrix();
  for (int k = 0; k < 4; ++k) {
    if (k != left_out_line && fit.points[static_cast<std::size_t>(k)] < options.min_points) {
      std::ostringstream message;
      message << "line " << k + 1 << " keeps " << fit.points[static_cast<std::size_t>(k)]
              << " of its stripe's points (min_points = " << options.min_points << ")";
      fit.message = message.str();
      fit.starved_line = k;
      return fit;
    }
  }
  fit.ok = true;
  return fit;
}

}  // namespace oal
