// The renderer in one translation unit: the ground truth, the per-sample drawing and the scene
// dressing (annotations, clutter, shadow, paper) share the plane geometry, and the per-pixel
// calls inline across them.
#include "scene/scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "base/random.h"
#include "detector/lens.h"
#include "detector/options.h"
#include "scene/geometry.h"

namespace oal {
namespace {

// Points closer to the camera plane than this are treated as behind the camera (metres).
constexpr double kMinDepthM = 1e-6;
// Rays meeting the board plane farther than this see background_grey (metres).
constexpr double kMaxDepthM = 1e6;
// Samples of a target line used to find its visible part, and to fit its distorted image.
constexpr int kVisibilitySamples = 1000;
constexpr int kFitSamples = 400;

bool InRange(double value, double lo, double hi) {
  return value >= lo && value <= hi;
}

// ---------------------------------------------------------------------------------------------
// Small 3D helpers.

using scene_geometry::Cross;
using scene_geometry::Vec3;

// cMo applied to the object point (X, Y, 0).
Vec3 ToCamera(const vpHomogeneousMatrix& cMo, double X, double Y) {
  return {cMo[0][0] * X + cMo[0][1] * Y + cMo[0][3], cMo[1][0] * X + cMo[1][1] * Y + cMo[1][3],
          cMo[2][0] * X + cMo[2][1] * Y + cMo[2][3]};
}

// The image of the 3D line through the camera-frame points a and b, in ideal pixels: the
// plane through the centre of projection and the line has normal a x b. False when the line
// passes through the centre of projection.
bool IdealLineOf(const Lens& camera, const Vec3& a, const Vec3& b, LineParams* out) {
  const Vec3 n = Cross(a, b);
  const double A = n.x / camera.px(), B = n.y / camera.py();
  const double C = n.z - A * camera.u0() - B * camera.v0();
  const double norm = std::hypot(A, B);
  if (!(norm > 1e-15 * std::fabs(C))) return false;
  *out = Normalized(-C / norm, std::atan2(B, A));
  return true;
}

Point2d IdealPixel(const Lens& camera, const Vec3& p) {
  return {camera.u0() + camera.px() * p.x / p.z, camera.v0() + camera.py() * p.y / p.z};
}

// ---------------------------------------------------------------------------------------------
// Ground truth.

// One target line seen by the camera: its centre line is c1 + t (c2 - c1), t in [0, 1].
class SegmentView {
 public:
  SegmentView(const RenderOptions& options, const Vec3& c1, const Vec3& c2)
      : options_(options), c1_(c1), c2_(c2) {}

  Vec3 At(double t) const {
    return {c1_.x + t * (c2_.x - c1_.x), c1_.y + t * (c2_.y - c1_.y), c1_.z + t * (c2_.z - c1_.z)};
  }

  // The distorted pixel of the point at t; false when behind the camera or outside the image.
  bool Inside(double t, Point2d* pixel) const {
    const Vec3 p = At(t);
    if (p.z <= kMinDepthM) return false;
    *pixel = options_.camera.Pixel(p.x / p.z, p.y / p.z);
    return pixel->u >= 0.0 && pixel->u <= options_.width - 1 && pixel->v >= 0.0 &&
           pixel->v <= options_.height - 1;
  }

  // Bisection between an inside parameter and an outside one; returns the inside end.
  double RefineEnd(double t_in, double t_out) const {
    Point2d unused;
    for (int i = 0; i < 60; ++i) {
      const double mid = 0.5 * (t_in + t_out);
      (Inside(mid, &unused) ? t_in : t_out) = mid;
    }
    return t_in;
  }

 private:
  const RenderOptions& options_;
  Vec3 c1_, c2_;
};

// The parameter range [*t_a, *t_b] of the visible part; false if fewer than two samples are
// inside the image.
bool VisibleRange(const SegmentView& view, double* t_a, double* t_b) {
  int first = -1, last = -1;
  Point2d unused;
  for (int i = 0; i < kVisibilitySamples; ++i) {
    if (!view.Inside(i / (kVisibilitySamples - 1.0), &unused)) continue;
    if (first < 0) first = i;
    last = i;
  }
  if (first < 0 || first == last) return false;
  const double step = 1.0 / (kVisibilitySamples - 1.0);
  *t_a = first == 0 ? 0.0 : view.RefineEnd(first * step, (first - 1) * step);
  *t_b = last == kVisibilitySamples - 1 ? 1.0 : view.RefineEnd(last * step, (last + 1) * step);
  return true;
}

// Apparent width of `line` at the centre-line parameter t, in ideal pixels.
double ApparentWidth(const TargetLine& line, const vpHomogeneousMatrix& cMo, const Lens& camera,
                     double t) {
  const double dx = line.x2_m - line.x1_m, dy = line.y2_m - line.y1_m;
  const double length = std::hypot(dx, dy);
  const double nx = -dy / length * 0.5 * line.width_m, ny = dx / length * 0.5 * line.width_m;
  const double mx = line.x1_m + t * dx, my = line.y1_m + t * dy;
  const Point2d centre = IdealPixel(camera, ToCamera(cMo, mx, my));
  double width = 0.0;
  for (const double side : {1.0, -1.0}) {
    const double ex = mx + side * nx, ey = my + side * ny;
    LineParams edge;
    if (!IdealLineOf(camera, ToCamera(cMo, ex, ey), ToCamera(cMo, ex + dx, ey + dy), &edge)) {
      return 0.0;
    }
    width += std::fabs(edge.SignedDistance(centre.u, centre.v));
  }
  return width;
}

TruthLine LineTruth(const TargetLine& line, int index, const vpHomogeneousMatrix& cMo,
                    const RenderOptions& options, const FrameEffects& effects) {
  TruthLine truth;
  truth.index = index;
  const Vec3 c1 = ToCamera(cMo, line.x1_m, line.y1_m);
  const Vec3 c2 = ToCamera(cMo, line.x2_m, line.y2_m);
  if (!IdealLineOf(options.camera, c1, c2, &truth.ideal)) return truth;
  const SegmentView view(options, c1, c2);
  double t_a = 0.0, t_b = 0.0;
  if (!VisibleRange(view, &t_a, &t_b)) return truth;

  std::vector<Point2d> points;
  std::vector<double> along;  // each point's parameter on the centre line
  points.reserve(kFitSamples);
  for (int i = 0; i < kFitSamples; ++i) {
    Point2d p;
    const double t = t_a + (t_b - t_a) * i / (kFitSamples - 1.0);
    if (view.Inside(t, &p)) {
      points.push_back(p);
      along.push_back(t);
    }
  }
  if (points.size() < 2) return truth;
  truth.visible = true;
  truth.distorted_fit = FitLine(points);
  view.Inside(t_a, &truth.end_a);
  view.Inside(t_b, &truth.end_b);
  truth.visible_length_px =
      std::hypot(truth.end_b.u - truth.end_a.u, truth.end_b.v - truth.end_a.v);
  truth.width_px = ApparentWidth(line, cMo, options.camera, 0.5 * (t_a + t_b));
  const std::vector<Occluder>& occluders = effects.occluders;
  const std::vector<PlaneOccluder>& on_plane = effects.plane_occluders;
  if (!occluders.empty() || !on_plane.empty()) {
    int hidden = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Point2d& p = points[i];
      const double X = line.x1_m + along[i] * (line.x2_m - line.x1_m);
      const double Y = line.y1_m + along[i] * (line.y2_m - line.y1_m);
      hidden += std::any_of(occluders.begin(), occluders.end(),
                            [&](const Occluder& o) { return o.Contains(p.u, p.v); }) ||
                std::any_of(on_plane.begin(), on_plane.end(),
                            [&](const PlaneOccluder& o) { return o.Contains(X, Y); });
    }
    truth.occluded_fraction = static_cast<double>(hidden) / static_cast<double>(points.size());
  }
  return truth;
}

// ---------------------------------------------------------------------------------------------
// Rendering.

// The half-plane a X + b Y + c <= 0 of the board plane, (a, b) a unit vector.
struct HalfPlane {
  double a = 0.0, b = 0.0, c = 0.0;
};
// A convex region of the board plane: the board, or one stripe (sides, then ends).
using Region = std::array<HalfPlane, 4>;

// Region 0 is the board, region i + 1 is target line i.
std::vector<Region> BuildRegions(const LineTarget& target) {
  const double hw = 0.5 * target.board_width_m, hh = 0.5 * target.board_height_m;
  std::vector<Region> regions;
  regions.push_back(Region{HalfPlane{1.0, 0.0, -hw}, HalfPlane{-1.0, 0.0, -hw},
                           HalfPlane{0.0, 1.0, -hh}, HalfPlane{0.0, -1.0, -hh}});
  for (const TargetLine& line : target.lines) {
    const double length = std::hypot(line.x2_m - line.x1_m, line.y2_m - line.y1_m);
    const double ex = (line.x2_m - line.x1_m) / length, ey = (line.y2_m - line.y1_m) / length;
    const double mx = -ey, my = ex;  // unit normal
    const double offset = mx * line.x1_m + my * line.y1_m;
    const double half = 0.5 * line.width_m;
    regions.push_back(Region{HalfPlane{mx, my, -offset - half}, HalfPlane{-mx, -my, offset - half},
                             HalfPlane{-ex, -ey, ex * line.x1_m + ey * line.y1_m},
                             HalfPlane{ex, ey, -(ex * line.x2_m + ey * line.y2_m)}});
  }
  return regions;
}

// Where the ray of a distorted pixel meets the board plane, with the derivatives of that point
// with respect to the pixel coordinates.
struct PlaneSample {
  double X = 0.0, Y = 0.0;                        // metres, object frame
  double Xu = 0.0, Xv = 0.0, Yu = 0.0, Yv = 0.0;  // metres per pixel
};

// Maps distorted pixels to the board plane for one pose. The plane point (X, Y) projects to
// the normalised point (x, y) with (x, y, 1) ~ G (X, Y, 1), G = [r1 r2 t] of cMo; so
// q = G^-1 (x, y, 1) gives X = q0 / q2, Y = q1 / q2 at depth 1 / q2.
class PlaneProjector {
 public:
  PlaneProjector(const vpHomogeneousMatrix& cMo, const Lens& camera) : camera_(camera) {
    const double g[3][3] = {{cMo[0][0], cMo[0][1], cMo[0][3]},
                            {cMo[1][0], cMo[1][1], cMo[1][3]},
                            {cMo[2][0], cMo[2][1], cMo[2][3]}};
    const double det = g[0][0] * (g[1][1] * g[2][2] - g[1][2] * g[2][1]) -
                       g[0][1] * (g[1][0] * g[2][2] - g[1][2] * g[2][0]) +
                       g[0][2] * (g[1][0] * g[2][1] - g[1][1] * g[2][0]);
    valid_ = std::fabs(det) > 1e-12;  // otherwise the camera centre lies in the plane
    if (!valid_) return;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) {
        // Inverse via the adjugate: inv[r][c] = cofactor[c][r] / det.
        const int r1 = (c + 1) % 3, r2 = (c + 2) % 3, c1 = (r + 1) % 3, c2 = (r + 2) % 3;
        inv_[r][c] = (g[r1][c1] * g[r2][c2] - g[r1][c2] * g[r2][c1]) / det;
      }
    }
  }

  // False when the ray of pixel (u, v), whose normalised coordinates are (x, y), misses the
  // plane in front of the camera.
  bool Sample(int u, int v, double x, double y, PlaneSample* s) const {
    if (!valid_) return false;
    const double q2 = inv_[2][0] * x + inv_[2][1] * y + inv_[2][2];
    if (!(q2 > 1.0 / kMaxDepthM)) return false;
    const double w = 1.0 / q2;
    s->X = (inv_[0][0] * x + inv_[0][1] * y + inv_[0][2]) * w;
    s->Y = (inv_[1][0] * x + inv_[1][1] * y + inv_[1][2]) * w;
    // d(X, Y)/d(x, y).
    const double Xx = (inv_[0][0] - s->X * inv_[2][0]) * w;
    const double Xy = (inv_[0][1] - s->X * inv_[2][1]) * w;
    const double Yx = (inv_[1][0] - s->Y * inv_[2][0]) * w;
    const double Yy = (inv_[1][1] - s->Y * inv_[2][1]) * w;
    const auto [xu, xv, yu, yv] = camera_.NormalisedDerivative(u, v, Point2d{x, y});
    s->Xu = Xx * xu + Xy * yu;
    s->Xv = Xx * xv + Xy * yv;
    s->Yu = Yx * xu + Yy * yu;
    s->Yv = Yx * xv + Yy * yv;
    return true;
  }

 private:
  Lens camera_;
  double inv_[3][3] = {};
  bool valid_ = false;
};

// P(nu U + nv V <= t) for U, V uniform in [-h/2, h/2]: the fraction of a square of side h
// on the negative side of a line at signed distance -t from its centre. a = h |nu|, b = h |nv|;
// the density of nu U + nv V is the trapezoid box(a) * box(b).
double SquareCoverage(double t, double a, double b) {
  if (a < b) std::swap(a, b);
  const double half = 0.5 * (a + b);
  if (t <= -half) return 0.0;
  if (t >= half) return 1.0;
  const double flat = 0.5 * (a - b);
  if (t < -flat) return (t + half) * (t + half) / (2.0 * a * b);
  if (t > flat) return 1.0 - (half - t) * (half - t) / (2.0 * a * b);
  return t / a + 0.5;
}

// Fractions of a pixel covered by the board and by dark stripes on it.
struct Coverage {
  double board = 0.0;
  double dark = 0.0;
};

// Computes the coverage of one pixel at a time from its PlaneSample.
class PixelCoverage {
 public:
  PixelCoverage(std::vector<Region> regions, int supersample)
      : regions_(std::move(regions)), supersample_(supersample) {}

  Coverage Of(const PlaneSample& s) {
    if (!Classify(s)) return Coverage{};
    if (!NeedsSupersampling()) return At(0.0, 0.0, 1.0);
    Coverage sum;
    const double h = 1.0 / supersample_;
    for (int j = 0; j < supersample_; ++j) {
      for (int i = 0; i < supersample_; ++i) {
        const Coverage c = At((i + 0.5) * h - 0.5, (j + 0.5) * h - 0.5, h);
        sum.board += c.board;
        sum.dark += c.dark;
      }
    }
    const double n = static_cast<double>(supersample_) * supersample_;
    return Coverage{sum.board / n, sum.dark / n};
  }

 private:
  // An edge that passes within reach of the pixel, in pixel units: signed distance of the
  // pixel centre (positive outside the region) and unit normal.
  struct PartialEdge {
    int region = 0;
    int edge = 0;
    double s0 = 0.0, nu = 0.0, nv = 0.0;
  };

  // Sorts each region's edges into inside, outside or partial for this pixel. False when the
  // pixel is entirely off the board.
  bool Classify(const PlaneSample& s) {
    // Every point of the pixel is within 0.71 px of its centre, i.e. within 0.71 * |J|_F of
    // the centre's plane point (|J|_F bounds the largest stretch). The margin covers the
    // non-linearity of the map across one pixel.
    const double reach2 = 0.5625 * (s.Xu * s.Xu + s.Xv * s.Xv + s.Yu * s.Yu + s.Yv * s.Yv);
    partial_.clear();
    full_stripes_ = 0;
    for (std::size_t r = 0; r < regions_.size(); ++r) {
      const std::size_t first = partial_.size();
      bool out = false;
      for (int e = 0; e < 4 && !out; ++e) {
        const HalfPlane& h = regions_[r][e];
        const double d = h.a * s.X + h.b * s.Y + h.c;
        if (d * d > reach2) {
          out = d > 0.0;
        } else {
          partial_.push_back(Partial(static_cast<int>(r), e, h, d, s));
        }
      }
      if (out) {
        partial_.resize(first);
        if (r == 0) return false;
      } else if (r > 0 && partial_.size() == first) {
        ++full_stripes_;
      }
    }
    return true;
  }

  static PartialEdge Partial(int region, int edge, const HalfPlane& h, double d,
                             const PlaneSample& s) {
    const double gu = h.a * s.Xu + h.b * s.Yu, gv = h.a * s.Xv + h.b * s.Yv;
    const double inv = 1.0 / std::max(std::hypot(gu, gv), 1e-300);
    return PartialEdge{region, edge, d * inv, gu * inv, gv * inv};
  }

  // One edge, or the two (parallel) sides of one stripe, are covered exactly by At(); any
  // other combination is an intersection or union of non-parallel edges.
  bool NeedsSupersampling() const {
    if (partial_.size() <= 1) return false;
    return !(partial_.size() == 2 && partial_[0].region == partial_[1].region &&
             partial_[0].region > 0 && partial_[0].edge == 0 && partial_[1].edge == 1);
  }

  // Coverage of the square of side h centred at (du, dv) pixels from the pixel centre. A
  // region's coverage is 1 - sum(1 - c_edge) over its partial edges (exact for one edge and for
  // two parallel opposite edges); stripes add up to at most the board.
  Coverage At(double du, double dv, double h) const {
    Coverage c{1.0, static_cast<double>(full_stripes_)};
    std::size_t i = 0;
    while (i < partial_.size()) {
      const int region = partial_[i].region;
      double region_cover = 1.0;
      for (; i < partial_.size() && partial_[i].region == region; ++i) {
        const PartialEdge& e = partial_[i];
        const double s = e.s0 + e.nu * du + e.nv * dv;
        region_cover -= 1.0 - SquareCoverage(-s, h * std::fabs(e.nu), h * std::fabs(e.nv));
      }
      region_cover = std::max(region_cover, 0.0);
      if (region == 0) {
        c.board = region_cover;
      } else {
        c.dark += region_cover;
      }
    }
    c.dark = std::min({c.dark, 1.0, c.board});
    return c;
  }

  std::vector<Region> regions_;
  int supersample_;
  std::vector<PartialEdge> partial_;
  int full_stripes_ = 0;
};

// What is seen around the board: a grey level, or an image tiled on the board plane.
class BackgroundShade {
 public:
  BackgroundShade(const vpImage<unsigned char>& image, double texel_m, double grey)
      : image_(image), texel_m_(texel_m), grey_(grey) {}

  double At(double X, double Y) const {
    if (image_.getSize() == 0) return grey_;
    const double fx = X / texel_m_, fy = Y / texel_m_;
    if (!(std::fabs(fx) < 1e9 && std::fabs(fy) < 1e9)) return grey_;
    const double x0 = std::floor(fx), y0 = std::floor(fy);
    const double ax = fx - x0, ay = fy - y0;
    const int w = static_cast<int>(image_.getWidth()), h = static_cast<int>(image_.getHeight());
    const int i0 = Wrap(x0, w), i1 = (i0 + 1) % w, j0 = Wrap(y0, h), j1 = (j0 + 1) % h;
    const double top = (1.0 - ax) * image_[j0][i0] + ax * image_[j0][i1];
    const double bottom = (1.0 - ax) * image_[j1][i0] + ax * image_[j1][i1];
    return (1.0 - ay) * top + ay * bottom;
  }

 private:
  static int Wrap(double index, int size) {
    const long long i = static_cast<long long>(index) % size;
    return static_cast<int>(i < 0 ? i + size : i);
  }

  const vpImage<unsigned char>& image_;
  double texel_m_;
  double grey_;
};

// Multiplies by 1 - gradient * t, t in [0, 1] across the image along `angle_rad`.
void ApplyIllumination(double gradient, double angle_rad, cv::Mat1f* image) {
  if (gradient <= 0.0) return;
  const double c = std::cos(angle_rad), s = std::sin(angle_rad);
  const double w = image->cols - 1.0, h = image->rows - 1.0;
  const double t_min = std::min({0.0, w * c, h * s, w * c + h * s});
  const double t_max = std::max({0.0, w * c, h * s, w * c + h * s});
  for (int v = 0; v < image->rows; ++v) {
    float* row = image->ptr<float>(v);
    for (int u = 0; u < image->cols; ++u) {
      const double t = (u * c + v * s - t_min) / (t_max - t_min);
      row[u] = static_cast<float>(row[u] * (1.0 - gradient * t));
    }
  }
}

// Multiplies by the vignetting 1 - k (r / r_corner)^2, r from the principal point, and by the
// hot spot 1 + g exp(-d^2 / (2 s^2)); both are separable, so they are tabulated per column and
// per row.
void ApplyLightFalloff(const RenderOptions& options, cv::Mat1f* image) {
  if (options.vignetting <= 0.0 && options.hot_spot_gain <= 0.0) return;
  const double u0 = options.camera.u0(), v0 = options.camera.v0();
  const double w = image->cols - 1.0, h = image->rows - 1.0;
  double corner2 = 0.0;
  for (const double cu : {0.0, w}) {
    for (const double cv : {0.0, h}) {
      corner2 = std::max(corner2, (cu - u0) * (cu - u0) + (cv - v0) * (cv - v0));
    }
  }
  const double k = options.vignetting / std::max(corner2, 1e-12);
  const double hu = options.hot_spot_u * w, hv = options.hot_spot_v * h;
  const double sigma = options.hot_spot_sigma * std::hypot(static_cast<double>(image->cols),
                                                           static_cast<double>(image->rows));
  const double inv_2s2 = 1.0 / (2.0 * sigma * sigma);
  // r^2 = ru[u] + rv[v]; the spot's Gaussian = gu[u] * gv[v].
  std::vector<double> ru(image->cols), gu(image->cols);
  for (int u = 0; u < image->cols; ++u) {
    ru[u] = (u - u0) * (u - u0);
    gu[u] = std::exp(-(u - hu) * (u - hu) * inv_2s2);
  }
  for (int v = 0; v < image->rows; ++v) {
    const double rv = (v - v0) * (v - v0);
    const double gv = options.hot_spot_gain * std::exp(-(v - hv) * (v - hv) * inv_2s2);
    float* row = image->ptr<float>(v);
    for (int u = 0; u < image->cols; ++u) {
      const double factor = (1.0 - k * (ru[u] + rv)) * (1.0 + gv * gu[u]);
      row[u] = static_cast<float>(row[u] * factor);
    }
  }
}

// Fraction of the pixel square [lo, lo + 1] inside [a, b] (one axis).
double Overlap(double lo, double a, double b) {
  return std::clamp(std::min(lo + 1.0, b) - std::max(lo, a), 0.0, 1.0);
}

// Fraction of pixel (u, v) covered by `o`: exact for a rectangle, from the distance to the rim
// for a disc (exact for a straight rim; the error is second order in 1 / radius).
double OccluderCoverage(const Occluder& o, int u, int v) {
  if (o.shape == Occluder::Shape::kRectangle) {
    return Overlap(u - 0.5, o.centre_u_px - o.half_width_px, o.centre_u_px + o.half_width_px) *
           Overlap(v - 0.5, o.centre_v_px - o.half_height_px, o.centre_v_px + o.half_height_px);
  }
  const double distance = std::hypot(u - o.centre_u_px, v - o.centre_v_px);
  return std::clamp(o.half_width_px - distance + 0.5, 0.0, 1.0);
}

// Paints the occluders over the radiance, blending by coverage at their rims.
void PaintOccluders(const std::vector<Occluder>& occluders, cv::Mat1f* image) {
  for (const Occluder& o : occluders) {
    const double half_v = o.shape == Occluder::Shape::kDisc ? o.half_width_px : o.half_height_px;
    const int u_begin = std::max(0, static_cast<int>(std::floor(o.centre_u_px - o.half_width_px)));
    const int u_end =
        std::min(image->cols - 1, static_cast<int>(std::ceil(o.centre_u_px + o.half_width_px)));
    const int v_begin = std::max(0, static_cast<int>(std::floor(o.centre_v_px - half_v)));
    const int v_end =
        std::min(image->rows - 1, static_cast<int>(std::ceil(o.centre_v_px + half_v)));
    for (int v = v_begin; v <= v_end; ++v) {
      float* row = image->ptr<float>(v);
      for (int u = u_begin; u <= u_end; ++u) {
        const double c = OccluderCoverage(o, u, v);
        row[u] = static_cast<float>(row[u] * (1.0 - c) + o.grey * c);
      }
    }
  }
}

// Maps every grey level g to gain * g + offset.
void ApplyGainOffset(double gain, double offset, cv::Mat1f* image) {
  if (gain == 1.0 && offset == 0.0) return;
  image->convertTo(*image, CV_32F, gain, offset);
}

void AddNoise(double sigma, std::uint64_t seed, cv::Mat1f* image) {
  if (sigma <= 0.0) return;
  cv::RNG rng(SplitMix64(seed));
  cv::Mat1f noise(image->size());
  rng.fill(noise, cv::RNG::NORMAL, 0.0, sigma);
  *image += noise;
}

// ---------------------------------------------------------------------------------------------
// Pose sampling.

// Uniform in [0, 1) from 53 random bits (std::mt19937_64 is specified exactly by the standard,
// unlike the standard distributions, so poses are the same on every platform).
double Uniform(std::mt19937_64& gen) {
  return static_cast<double>(gen() >> 11) * 0x1.0p-53;
}

vpHomogeneousMatrix DrawPose(const PoseSampling& sampling, std::mt19937_64& gen) {
  const double deg = kPi / 180.0;
  const double offset = sampling.max_offset_m * std::sqrt(Uniform(gen));
  const double offset_angle = 2.0 * kPi * Uniform(gen);
  const double distance =
      sampling.min_distance_m + (sampling.max_distance_m - sampling.min_distance_m) * Uniform(gen);
  const double tilt = sampling.min_tilt_deg * deg +
                      (sampling.max_tilt_deg - sampling.min_tilt_deg) * deg * Uniform(gen);
  const double azimuth = 2.0 * kPi * Uniform(gen);
  const double roll = sampling.any_roll ? 2.0 * kPi * Uniform(gen)
                                        : sampling.max_tilt_deg * deg * (2.0 * Uniform(gen) - 1.0);

  // Camera axes in the object frame: z along the optical axis, into the board (+z_o side).
  const Vec3 z{std::sin(tilt) * std::cos(azimuth), std::sin(tilt) * std::sin(azimuth),
               std::cos(tilt)};
  Vec3 x0{1.0 - z.x * z.x, -z.x * z.y, -z.x * z.z};  // object x made orthogonal to z
  const double norm = std::sqrt(x0.x * x0.x + x0.y * x0.y + x0.z * x0.z);
  x0 = {x0.x / norm, x0.y / norm, x0.z / norm};
  const Vec3 y0 = Cross(z, x0);
  const double cr = std::cos(roll), sr = std::sin(roll);
  const Vec3 x{cr * x0.x + sr * y0.x, cr * x0.y + sr * y0.y, cr * x0.z + sr * y0.z};
  const Vec3 y{-sr * x0.x + cr * y0.x, -sr * x0.y + cr * y0.y, -sr * x0.z + cr * y0.z};
  const Vec3 centre{offset * std::cos(offset_angle) - distance * z.x,
                    offset * std::sin(offset_angle) - distance * z.y, -distance * z.z};

  return scene_geometry::PoseFromCameraAxes(x, y, z, centre);
}

bool LongEnough(const std::vector<TruthLine>& truth, double min_length_px) {
  return std::all_of(truth.begin(), truth.end(), [min_length_px](const TruthLine& line) {
    return line.visible && line.visible_length_px >= min_length_px;
  });
}

// ---------------------------------------------------------------------------------------------
// Scene dressing: what lies on the board plane besides the stripes (annotations printed on the
// board, clutter on the surface, the board's shadow, the paper's texture).

// Annotations: at least this far from every stripe and this far inside the board, 1 mm apart.
constexpr double kAnnotationClearanceM = 0.005;
constexpr double kAnnotationEdgeM = 0.004;
constexpr double kAnnotationGapM = 0.001;
// Their texels, text cap height and strokes (metres).
constexpr double kAnnotationTexelM = 0.0001;
constexpr double kAnnotationTextM = 0.003;
constexpr double kAnnotationStrokeM = 0.00035;
// Clutter: at least this far from the board; the texel of a clutter sheet's picture.
constexpr double kClutterGapM = 0.010;
constexpr double kClutterTexelM = 0.0004;
constexpr int kClutterPlacementDraws = 100;
// Plane boxes used to skip items are grown by this much (their anti-aliased rims reach
// half a pixel's footprint beyond them).
constexpr double kCullMarginM = 0.01;
// Cells of the paper's value noise (metres).
constexpr double kPaperCellM = 0.001;

// A convex quadrilateral on the board plane, corners in order around it.
using Quad = std::array<std::array<double, 2>, 4>;

Quad RotatedRect(double cx, double cy, double angle_rad, double half_x, double half_y) {
  const double c = std::cos(angle_rad), s = std::sin(angle_rad);
  const double sx[4] = {-1.0, 1.0, 1.0, -1.0}, sy[4] = {-1.0, -1.0, 1.0, 1.0};
  Quad q;
  for (int i = 0; i < 4; ++i) {
    const double lx = sx[i] * half_x, ly = sy[i] * half_y;
    q[i] = {cx + c * lx - s * ly, cy + s * lx + c * ly};
  }
  return q;
}

// True when the convex quadrilaterals overlap or touch (separating axis theorem).
bool QuadsOverlap(const Quad& a, const Quad& b) {
  for (const Quad* q : {&a, &b}) {
    for (int i = 0; i < 4; ++i) {
      const auto& p0 = (*q)[i];
      const auto& p1 = (*q)[(i + 1) % 4];
      const double nx = p0[1] - p1[1], ny = p1[0] - p0[0];
      double a_lo = 1e300, a_hi = -1e300, b_lo = 1e300, b_hi = -1e300;
      for (int j = 0; j < 4; ++j) {
        const double pa = nx * a[j][0] + ny * a[j][1], pb = nx * b[j][0] + ny * b[j][1];
        a_lo = std::min(a_lo, pa);
        a_hi = std::max(a_hi, pa);
        b_lo = std::min(b_lo, pb);
        b_hi = std::max(b_hi, pb);
      }
      if (a_hi < b_lo || b_hi < a_lo) return false;
    }
  }
  return true;
}

// The rectangle each stripe covers.
std::vector<Quad> StripeQuads(const LineTarget& target) {
  std::vector<Quad> quads;
  for (const TargetLine& line : target.lines) {
    const double dx = line.x2_m - line.x1_m, dy = line.y2_m - line.y1_m;
    quads.push_back(RotatedRect(0.5 * (line.x1_m + line.x2_m), 0.5 * (line.y1_m + line.y2_m),
                                std::atan2(dy, dx), 0.5 * std::hypot(dx, dy), 0.5 * line.width_m));
  }
  return quads;
}

// An axis-aligned box of the plane.
struct Box {
  double min_x = 0.0, min_y = 0.0, max_x = 0.0, max_y = 0.0;

  static Box Of(const Quad& q, double margin) {
    Box b{1e300, 1e300, -1e300, -1e300};
    for (const auto& p : q) {
      b.min_x = std::min(b.min_x, p[0] - margin);
      b.min_y = std::min(b.min_y, p[1] - margin);
      b.max_x = std::max(b.max_x, p[0] + margin);
      b.max_y = std::max(b.max_y, p[1] + margin);
    }
    return b;
  }
  bool Contains(double X, double Y) const {
    return X >= min_x && X <= max_x && Y >= min_y && Y <= max_y;
  }
};

// The length on the plane of one pixel's longer side at the sample s (metres).
double Footprint(const PlaneSample& s) {
  return std::sqrt(std::max(s.Xu * s.Xu + s.Yu * s.Yu, s.Xv * s.Xv + s.Yv * s.Yv));
}

// A picture lying on the board plane (an annotation printed on the board, a sheet of clutter):
// premultiplied (grey * alpha, alpha) texels in its own frame, with an area-averaged pyramid
// (OpenCV INTER_AREA) so that a pixel sees about the mean of the texels under it, not one of
// them; levels are blended trilinearly by the pixel's footprint.
class Decal {
 public:
  // `grey` and `alpha` (0: transparent, 255: opaque) of one size, one texel = texel_m on the
  // plane; the picture's centre lies at (centre_x, centre_y), its rows run along angle_rad from
  // the object x axis and its columns along angle_rad + pi/2. With `sharp_texels`, a texel is
  // a sharp square where a pixel is smaller than it (a printed marker), not a sample
  // interpolated bilinearly with its neighbours.
  Decal(const cv::Mat1b& grey, const cv::Mat1b& alpha, double texel_m, double centre_x,
        double centre_y, double angle_rad, bool sharp_texels = false)
      : sharp_texels_(sharp_texels),
        texel_m_(texel_m),
        width_m_(grey.cols * texel_m),
        height_m_(grey.rows * texel_m),
        cos_(std::cos(angle_rad)),
        sin_(std::sin(angle_rad)) {
    origin_x_ = centre_x - 0.5 * (cos_ * width_m_ - sin_ * height_m_);
    origin_y_ = centre_y - 0.5 * (sin_ * width_m_ + cos_ * height_m_);
    box_ = Box::Of(RotatedRect(centre_x, centre_y, angle_rad, 0.5 * width_m_, 0.5 * height_m_),
                   kCullMarginM);
    cv::Mat1f a, p;
    alpha.convertTo(a, CV_32F, 1.0 / 255.0);
    grey.convertTo(p, CV_32F);
    const std::vector<cv::Mat> channels = {p.mul(a), a};
    cv::Mat level;
    cv::merge(channels, level);
    levels_.push_back(level);
    while (level.cols > 1 || level.rows > 1) {
      cv::Mat next;
      cv::resize(level, next, cv::Size((level.cols + 1) / 2, (level.rows + 1) / 2), 0.0, 0.0,
                 cv::INTER_AREA);
      levels_.push_back(next);
      level = next;
    }
  }

  const Box& box() const { return box_; }

  // `under` seen through the decal at the plane point (X, Y), for a pixel of footprint_m.
  double Over(double under, double X, double Y, double footprint_m) const {
    if (!box_.Contains(X, Y)) return under;
    const double dx = X - origin_x_, dy = Y - origin_y_;
    const double lx = cos_ * dx + sin_ * dy, ly = -sin_ * dx + cos_ * dy;
    if (sharp_texels_ && footprint_m < texel_m_) {
      // The box of side footprint_m around the point over sharp texels: the bilinear weights
      // steepened by texel / footprint (equal to them at footprint = texel, where the pyramid
      // takes over).
      const cv::Vec2d texel = Sample(0, lx, ly, texel_m_ / std::max(footprint_m, 1e-300));
      return under * (1.0 - texel[1]) + texel[0];
    }
    const double lod = std::log2(std::max(footprint_m / texel_m_, 1.0));
    const int last = static_cast<int>(levels_.size()) - 1;
    const int l0 = std::min(static_cast<int>(lod), last);
    cv::Vec2d texel = Sample(l0, lx, ly);
    if (l0 < last && lod > l0) {
      const double t = lod - l0;
      texel = (1.0 - t) * texel + t * Sample(l0 + 1, lx, ly);
    }
    return under * (1.0 - texel[1]) + texel[0];
  }

 private:
  // Bilinear (premultiplied grey, alpha) of level `level` at the local point (lx, ly) metres;
  // transparent outside the picture. `steepen` > 1 moves the weights away from 1/2 by that
  // factor (clamped to [0, 1]): the mean over a box that many times smaller than a texel.
  cv::Vec2d Sample(int level, double lx, double ly, double steepen = 1.0) const {
    const cv::Mat& m = levels_[level];
    const double cx = lx / width_m_ * m.cols - 0.5, cy = ly / height_m_ * m.rows - 0.5;
    if (!(cx > -1.0 && cy > -1.0 && cx < m.cols && cy < m.rows)) return cv::Vec2d(0.0, 0.0);
    const double fx = std::floor(cx), fy = std::floor(cy);
    const int i0 = static_cast<int>(fx), j0 = static_cast<int>(fy);
    double ax = cx - fx, ay = cy - fy;
    if (steepen != 1.0) {
      ax = std::clamp((ax - 0.5) * steepen + 0.5, 0.0, 1.0);
      ay = std::clamp((ay - 0.5) * steepen + 0.5, 0.0, 1.0);
    }
    const auto at = [&m](int i, int j) {
      if (i < 0 || j < 0 || i >= m.cols || j >= m.rows) return cv::Vec2d(0.0, 0.0);
      return cv::Vec2d(m.at<cv::Vec2f>(j, i));
    };
    return (1.0 - ay) * ((1.0 - ax) * at(i0, j0) + ax * at(i0 + 1, j0)) +
           ay * ((1.0 - ax) * at(i0, j0 + 1) + ax * at(i0 + 1, j0 + 1));
  }

  bool sharp_texels_;
  double texel_m_, width_m_, height_m_, cos_, sin_;
  double origin_x_ = 0.0, origin_y_ = 0.0;  // plane point of the picture's (0, 0) corner
  Box box_;
  std::vector<cv::Mat> levels_;  // CV_32FC2, finest first
};

// A dark object lying on the surface (a tool): a rectangle or a disc, anti-aliased from the
// distance to its rim in pixels (exact for a straight rim away from corners).
struct BenchObject {
  bool disc = false;
  double cx = 0.0, cy = 0.0, cos = 1.0, sin = 0.0;
  double half_x = 0.0, half_y = 0.0;  // rectangle half sizes along its axes; disc: radius
  double grey = 40.0;
  Box box;

  Quad Outline() const {
    return RotatedRect(cx, cy, std::atan2(sin, cos), half_x, disc ? half_x : half_y);
  }

  // Fraction of the pixel whose centre sees the plane sample s that the object covers.
  double Coverage(const PlaneSample& s) const {
    const double dx = s.X - cx, dy = s.Y - cy;
    if (disc) {
      const double r = std::hypot(dx, dy);
      const double nx = r > 0.0 ? dx / r : 1.0, ny = r > 0.0 ? dy / r : 0.0;
      const double g = std::hypot(nx * s.Xu + ny * s.Yu, nx * s.Xv + ny * s.Yv);  // m / px
      return std::clamp(0.5 + (half_x - r) / std::max(g, 1e-300), 0.0, 1.0);
    }
    const double lx = cos * dx + sin * dy, ly = -sin * dx + cos * dy;
    const double gx = std::hypot(cos * s.Xu + sin * s.Yu, cos * s.Xv + sin * s.Yv);
    const double gy = std::hypot(-sin * s.Xu + cos * s.Yu, -sin * s.Xv + cos * s.Yv);
    return std::clamp(0.5 + (half_x - std::fabs(lx)) / std::max(gx, 1e-300), 0.0, 1.0) *
           std::clamp(0.5 + (half_y - std::fabs(ly)) / std::max(gy, 1e-300), 0.0, 1.0);
  }
};

// Items binned on a square grid of the plane by their boxes, so that a pixel looks only at the
// few whose box covers its cell (in drawing order).
class PlaneGrid {
 public:
  PlaneGrid() = default;
  explicit PlaneGrid(const std::vector<Box>& boxes) {
    if (boxes.empty()) return;
    bounds_ = boxes[0];
    for (const Box& b : boxes) {
      bounds_.min_x = std::min(bounds_.min_x, b.min_x);
      bounds_.min_y = std::min(bounds_.min_y, b.min_y);
      bounds_.max_x = std::max(bounds_.max_x, b.max_x);
      bounds_.max_y = std::max(bounds_.max_y, b.max_y);
    }
    const double extent = std::max(bounds_.max_x - bounds_.min_x, bounds_.max_y - bounds_.min_y);
    cell_m_ = std::max(0.05, extent / 128.0);
    nx_ = static_cast<int>((bounds_.max_x - bounds_.min_x) / cell_m_) + 1;
    ny_ = static_cast<int>((bounds_.max_y - bounds_.min_y) / cell_m_) + 1;
    cells_.resize(static_cast<std::size_t>(nx_) * ny_);
    for (std::size_t id = 0; id < boxes.size(); ++id) {
      const Box& b = boxes[id];
      const int i0 = Cell(b.min_x, bounds_.min_x, nx_), i1 = Cell(b.max_x, bounds_.min_x, nx_);
      const int j0 = Cell(b.min_y, bounds_.min_y, ny_), j1 = Cell(b.max_y, bounds_.min_y, ny_);
      for (int j = j0; j <= j1; ++j) {
        for (int i = i0; i <= i1; ++i) {
          cells_[static_cast<std::size_t>(j) * nx_ + i].push_back(static_cast<int>(id));
        }
      }
    }
  }

  // The items whose box may contain (X, Y); null when none.
  const std::vector<int>* At(double X, double Y) const {
    if (cells_.empty() || !bounds_.Contains(X, Y)) return nullptr;
    const std::vector<int>& cell =
        cells_[static_cast<std::size_t>(Cell(Y, bounds_.min_y, ny_)) * nx_ +
               Cell(X, bounds_.min_x, nx_)];
    return cell.empty() ? nullptr : &cell;
  }

 private:
  int Cell(double value, double lo, int n) const {
    return std::clamp(static_cast<int>((value - lo) / cell_m_), 0, n - 1);
  }

  Box bounds_;
  double cell_m_ = 1.0;
  int nx_ = 0, ny_ = 0;
  std::vector<std::vector<int>> cells_;
};

// Smooth value noise in [-1, 1] on cells of cell_m of the plane.
double ValueNoise(double X, double Y, double cell_m, std::uint64_t seed) {
  const double fx = X / cell_m, fy = Y / cell_m;
  if (!(std::fabs(fx) < 1e9 && std::fabs(fy) < 1e9)) return 0.0;
  const double x0 = std::floor(fx), y0 = std::floor(fy);
  const double ax = fx - x0, ay = fy - y0;
  const auto lattice = [seed](double i, double j) {
    const auto key = static_cast<std::uint64_t>(static_cast<long long>(i)) * 0x9E3779B97F4A7C15ull ^
                     static_cast<std::uint64_t>(static_cast<long long>(j));
    return static_cast<double>(SplitMix64(seed ^ SplitMix64(key)) >> 11) * 0x1.0p-52 - 1.0;
  };
  const double top = (1.0 - ax) * lattice(x0, y0) + ax * lattice(x0 + 1.0, y0);
  const double bottom = (1.0 - ax) * lattice(x0, y0 + 1.0) + ax * lattice(x0 + 1.0, y0 + 1.0);
  return (1.0 - ay) * top + ay * bottom;
}

double PaperNoise(double X, double Y, std::uint64_t seed) {
  return ValueNoise(X, Y, kPaperCellM, seed);
}

// Text in OpenCV's Hershey simplex font, lines from top to bottom, cap height cap_m, strokes
// of about stroke_m, in an 8-bit mask (255: ink) of texel_m texels cropped to the ink with a
// 2-texel transparent border.
cv::Mat1b TextMask(const std::vector<std::string>& lines, double cap_m, double stroke_m,
                   double texel_m) {
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  const int thickness = std::max(1, static_cast<int>(std::lround(stroke_m / texel_m)));
  int baseline = 0;
  const cv::Size unit = cv::getTextSize("H", font, 1.0, 1, &baseline);
  const double scale = cap_m / texel_m / unit.height;
  const int pitch = static_cast<int>(std::ceil(1.7 * cap_m / texel_m));
  int width = 0;
  for (const std::string& line : lines) {
    width = std::max(width, cv::getTextSize(line, font, scale, thickness, &baseline).width);
  }
  const int pad = 4 * thickness;
  cv::Mat1b mask(pad * 2 + pitch * static_cast<int>(lines.size()), width + 2 * pad,
                 static_cast<unsigned char>(0));
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const int y = pad + static_cast<int>(std::ceil(cap_m / texel_m)) + static_cast<int>(i) * pitch;
    cv::putText(mask, lines[i], cv::Point(pad, y), font, scale, cv::Scalar(255), thickness,
                cv::LINE_AA);
  }
  std::vector<cv::Point> ink;
  cv::findNonZero(mask, ink);
  if (ink.empty()) return cv::Mat1b(4, 4, static_cast<unsigned char>(0));
  cv::Rect crop = cv::boundingRect(ink);
  crop.x -= 2;
  crop.y -= 2;
  crop.width += 4;
  crop.height += 4;
  crop &= cv::Rect(0, 0, mask.cols, mask.rows);
  return mask(crop).clone();
}

// A scale bar of length_m: a 0.35 mm bar, ticks every 10 mm (taller at both ends and the
// middle) above it and "<length> mm" below it, in an 8-bit mask of kAnnotationTexelM texels.
cv::Mat1b ScaleBarMask(double length_m) {
  const double t = kAnnotationTexelM;
  const auto px = [t](double m) { return static_cast<int>(std::lround(m / t)); };
  const cv::Mat1b label = TextMask({std::to_string(std::lround(length_m * 1000.0)) + " mm"},
                                   0.6 * kAnnotationTextM, kAnnotationStrokeM, t);
  const int pad = 2, stroke = px(kAnnotationStrokeM), tall = px(0.003), tick = px(0.002);
  const int width = px(length_m) + stroke + 2 * pad;
  const int bar_top = pad + tall;
  cv::Mat1b mask(bar_top + stroke + px(0.001) + label.rows + pad, std::max(width, label.cols),
                 static_cast<unsigned char>(0));
  cv::rectangle(mask, cv::Rect(pad, bar_top, px(length_m) + stroke, stroke), cv::Scalar(255),
                cv::FILLED);
  const int ticks = static_cast<int>(std::lround(length_m / 0.01));
  for (int i = 0; i <= ticks; ++i) {
    const int height = (i == 0 || i == ticks || 2 * i == ticks) ? tall : tick;
    cv::rectangle(mask, cv::Rect(pad + px(0.01 * i), bar_top - height, stroke, height),
                  cv::Scalar(255), cv::FILLED);
  }
  const int label_x = (mask.cols - label.cols) / 2, label_y = bar_top + stroke + px(0.001);
  label.copyTo(mask(cv::Rect(label_x, label_y, label.cols, label.rows)));
  return mask;
}

// Where annotation marks may go: inside the board by kAnnotationEdgeM, kAnnotationClearanceM
// clear of every stripe (and of a printed picture) and kAnnotationGapM clear of the marks
// placed before.
class AnnotationSpace {
 public:
  explicit AnnotationSpace(const LineTarget& target)
      : half_w_(0.5 * target.board_width_m - kAnnotationEdgeM),
        half_h_(0.5 * target.board_height_m - kAnnotationEdgeM),
        stripes_(StripeQuads(target)) {}

  // Marks keep kAnnotationClearanceM clear of `quad` too, as of a stripe.
  void KeepClearOf(const Quad& quad) { stripes_.push_back(quad); }

  // An axis-aligned mark of half sizes (hx, hy) centred at (cx, cy). A square grown by the
  // clearance contains the disc grown by it, so no overlap means at least the clearance.
  bool Fits(double cx, double cy, double hx, double hy) const {
    if (std::fabs(cx) + hx > half_w_ || std::fabs(cy) + hy > half_h_) return false;
    const Quad clear =
        RotatedRect(cx, cy, 0.0, hx + kAnnotationClearanceM, hy + kAnnotationClearanceM);
    for (const Quad& stripe : stripes_) {
      if (QuadsOverlap(clear, stripe)) return false;
    }
    const Quad apart = RotatedRect(cx, cy, 0.0, hx + kAnnotationGapM, hy + kAnnotationGapM);
    for (const Quad& mark : marks_) {
      if (QuadsOverlap(apart, mark)) return false;
    }
    return true;
  }

  void Take(double cx, double cy, double hx, double hy) {
    marks_.push_back(RotatedRect(cx, cy, 0.0, hx, hy));
  }

  // The free centre nearest to the board corner (sx * w/2, sy * h/2) on a grid of about 2 mm;
  // false when there is none.
  bool NearestToCorner(double sx, double sy, double hx, double hy, double* cx, double* cy) const {
    const double step = std::max(0.002, std::max(half_w_, half_h_) / 100.0);
    std::vector<std::pair<double, std::array<double, 2>>> candidates;
    for (double x = -half_w_ + hx; x <= half_w_ - hx; x += step) {
      for (double y = -half_h_ + hy; y <= half_h_ - hy; y += step) {
        const double ex = x - sx * half_w_, ey = y - sy * half_h_;
        candidates.push_back({ex * ex + ey * ey, {x, y}});
      }
    }
    std::sort(candidates.begin(), candidates.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    for (const auto& [unused, c] : candidates) {
      if (Fits(c[0], c[1], hx, hy)) {
        *cx = c[0];
        *cy = c[1];
        return true;
      }
    }
    return false;
  }

 private:
  double half_w_, half_h_;
  std::vector<Quad> stripes_;
  std::vector<Quad> marks_;
};

// The annotations `oalservo target` prints (approximately): line numbers beside both ends of
// each stripe, the name and "print at 100 %" near the top-left corner, the scale bar near the
// bottom-left one; all clear of `picture` (the printed picture's outline) when it is given.
std::vector<Decal> LayOutAnnotations(const LineTarget& target, int grey, const Quad* picture) {
  std::vector<Decal> decals;
  AnnotationSpace space(target);
  if (picture != nullptr) space.KeepClearOf(*picture);
  const auto add = [&](const cv::Mat1b& mask, double cx, double cy) {
    const double hx = 0.5 * mask.cols * kAnnotationTexelM, hy = 0.5 * mask.rows * kAnnotationTexelM;
    space.Take(cx, cy, hx, hy);
    decals.emplace_back(cv::Mat1b(mask.size(), static_cast<unsigned char>(grey)), mask,
                        kAnnotationTexelM, cx, cy, 0.0);
  };
  for (std::size_t i = 0; i < target.lines.size(); ++i) {
    const TargetLine& line = target.lines[i];
    const cv::Mat1b mask =
        TextMask({std::to_string(i + 1)}, kAnnotationTextM, kAnnotationStrokeM, kAnnotationTexelM);
    const double hx = 0.5 * mask.cols * kAnnotationTexelM, hy = 0.5 * mask.rows * kAnnotationTexelM;
    const double length = std::hypot(line.x2_m - line.x1_m, line.y2_m - line.y1_m);
    for (const int end : {0, 1}) {
      // e points from this end into the stripe, n across it.
      const double sign = end == 0 ? 1.0 : -1.0;
      const double ex = sign * (line.x2_m - line.x1_m) / length;
      const double ey = sign * (line.y2_m - line.y1_m) / length;
      const double nx = -ey, ny = ex;
      const double px = end == 0 ? line.x1_m : line.x2_m, py = end == 0 ? line.y1_m : line.y2_m;
      const double along = std::fabs(ex) * hx + std::fabs(ey) * hy;
      const double across = 0.5 * line.width_m + kAnnotationClearanceM + 0.0005 +
                            std::fabs(nx) * hx + std::fabs(ny) * hy;
      bool placed = false;
      for (int step = 0; step <= 20 && !placed; ++step) {
        const double t = along + 0.001 * step;
        for (const double side : {-1.0, 1.0}) {
          const double cx = px + ex * t + side * nx * across, cy = py + ey * t + side * ny * across;
          if (space.Fits(cx, cy, hx, hy)) {
            add(mask, cx, cy);
            placed = true;
            break;
          }
        }
      }
    }
  }
  const std::string name = target.name.empty() ? "target" : target.name;
  const cv::Mat1b title = TextMask({"oalservo " + name, "print at 100 %"}, kAnnotationTextM,
                                   kAnnotationStrokeM, kAnnotationTexelM);
  double cx = 0.0, cy = 0.0;
  if (space.NearestToCorner(-1.0, -1.0, 0.5 * title.cols * kAnnotationTexelM,
                            0.5 * title.rows * kAnnotationTexelM, &cx, &cy)) {
    add(title, cx, cy);
  }
  for (const double length_m : {0.1, 0.05}) {
    const cv::Mat1b bar = ScaleBarMask(length_m);
    if (space.NearestToCorner(-1.0, 1.0, 0.5 * bar.cols * kAnnotationTexelM,
                              0.5 * bar.rows * kAnnotationTexelM, &cx, &cy)) {
      add(bar, cx, cy);
      break;
    }
  }
  return decals;
}

// A sheet of printed text of w_m x h_m (portrait picture) on the surface: light paper, a
// heading and paragraphs of random words in Hershey simplex, 20 mm margins.
cv::Mat1b TextSheetPicture(double w_m, double h_m, std::mt19937_64& gen, cv::Mat1b* alpha) {
  const double t = kClutterTexelM;
  const int pad = 2;
  const int cols = static_cast<int>(std::lround(w_m / t)),
            rows = static_cast<int>(std::lround(h_m / t));
  const auto paper = static_cast<unsigned char>(190 + 45 * Uniform(gen));
  const double ink = 20 + 50 * Uniform(gen);
  cv::Mat1b grey(rows + 2 * pad, cols + 2 * pad, paper);
  *alpha = cv::Mat1b(grey.size(), static_cast<unsigned char>(0));
  (*alpha)(cv::Rect(pad, pad, cols, rows)).setTo(255);
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  int baseline = 0;
  const double unit = cv::getTextSize("H", font, 1.0, 1, &baseline).height;
  const auto word = [&gen](int letters) {
    std::string w;
    for (int i = 0; i < letters; ++i)
      w += static_cast<char>('a' + static_cast<int>(26 * Uniform(gen)));
    return w;
  };
  const int margin = static_cast<int>(0.02 / t);
  const int right = cols - margin;
  // Heading: cap height 4 mm, bolder.
  double y = margin + 0.004 / t;
  {
    std::string heading;
    const int words = 2 + static_cast<int>(3 * Uniform(gen));
    for (int i = 0; i < words; ++i)
      heading += (i ? " " : "") + word(3 + static_cast<int>(6 * Uniform(gen)));
    cv::putText(grey, heading, cv::Point(pad + margin, pad + static_cast<int>(y)), font,
                0.004 / t / unit, cv::Scalar(ink), 2, cv::LINE_AA);
  }
  // Body: cap height 2.2 mm, 5 mm line pitch, paragraphs of 3-8 lines.
  const double scale = 0.0022 / t / unit, pitch = 0.005 / t;
  y += 2.0 * pitch;
  while (y < rows - margin) {
    const int lines = 3 + static_cast<int>(6 * Uniform(gen));
    for (int l = 0; l < lines && y < rows - margin; ++l, y += pitch) {
      const int end =
          l + 1 == lines ? margin + static_cast<int>((right - margin) * Uniform(gen)) : right;
      std::string text;
      while (true) {
        const std::string next =
            (text.empty() ? "" : text + " ") + word(1 + static_cast<int>(9 * Uniform(gen)));
        if (margin + cv::getTextSize(next, font, scale, 1, &baseline).width > end) break;
        text = next;
      }
      cv::putText(grey, text, cv::Point(pad + margin, pad + static_cast<int>(y)), font, scale,
                  cv::Scalar(ink), 1, cv::LINE_AA);
    }
    y += pitch;
  }
  return grey;
}

// True when the disc (cx, cy, r) comes within `gap` of the rectangle |X| <= hw, |Y| <= hh.
bool DiscNearRect(double cx, double cy, double r, double hw, double hh, double gap) {
  const double dx = std::max(std::fabs(cx) - hw, 0.0), dy = std::max(std::fabs(cy) - hh, 0.0);
  return std::hypot(dx, dy) <= r + gap;
}

}  // namespace

// -------------------------------------------------------------------------------------------
// Scene dressing.

// Everything on the board plane besides the board and its stripes, laid out once by the
// renderer's constructor.
struct SceneDressing {
  // On the board: the paper's texture, then the printed picture (none, or one), then the
  // annotations.
  double paper_texture_grey = 0.0;
  std::uint64_t paper_seed = 0;
  std::vector<Decal> picture;
  std::vector<Decal> annotations;
  // On the surface, in drawing order: sheets, then objects; `clutter` bins them (ids: sheets
  // first).
  std::vector<Decal> sheets;
  std::vector<BenchObject> objects;
  PlaneGrid clutter;
  // The board's shadow: its outline moved to (shadow_x, shadow_y).
  double shadow_darkness = 0.0, shadow_x = 0.0, shadow_y = 0.0;
  double shadow_half_w = 0.0, shadow_half_h = 0.0, shadow_softness = 0.0;

  // The paper's grey at the plane sample s (the board's grey `board`, textured, annotated).
  double Paper(double board, const PlaneSample& s, double footprint_m) const {
    double value = board;
    if (paper_texture_grey > 0.0) value += paper_texture_grey * PaperNoise(s.X, s.Y, paper_seed);
    for (const Decal& decal : picture) value = decal.Over(value, s.X, s.Y, footprint_m);
    for (const Decal& decal : annotations) value = decal.Over(value, s.X, s.Y, footprint_m);
    return value;
  }

  // The surface's grey at the plane sample s: `background` under the clutter, in the shadow.
  double Surface(double background, const PlaneSample& s, double footprint_m) const {
    double value = background;
    if (const std::vector<int>* ids = clutter.At(s.X, s.Y)) {
      for (const int id : *ids) {
        if (static_cast<std::size_t>(id) < sheets.size()) {
          value = sheets[id].Over(value, s.X, s.Y, footprint_m);
          continue;
        }
        const BenchObject& object = objects[id - sheets.size()];
        if (!object.box.Contains(s.X, s.Y)) continue;
        value += object.Coverage(s) * (object.grey - value);
      }
    }
    if (shadow_darkness > 0.0) {
      // The penumbra is at least one pixel wide, so that the shadow's edge is anti-aliased.
      const double w = std::max(shadow_softness, footprint_m);
      const double in_x =
          std::clamp(0.5 + (shadow_half_w - std::fabs(s.X - shadow_x)) / w, 0.0, 1.0);
      const double in_y =
          std::clamp(0.5 + (shadow_half_h - std::fabs(s.Y - shadow_y)) / w, 0.0, 1.0);
      value *= 1.0 - shadow_darkness * in_x * in_y;
    }
    return value;
  }
};

namespace {

bool NeedsDressing(const RenderOptions& o) {
  return o.paper_texture_grey > 0.0 || o.annotations || o.shadow_darkness > 0.0 ||
         o.clutter_sheets > 0 || o.clutter_objects > 0 || !o.printed_picture.empty();
}

// The printed picture as a decal of the target's ink: opaque where the picture is black, the
// paper showing through where it is white; its outline on the plane in *outline.
Decal PrintedPictureDecal(const LineTarget& target, const RenderOptions& options, Quad* outline) {
  const vpImage<unsigned char>& picture = *options.printed_picture.image;
  const int rows = static_cast<int>(picture.getHeight()),
            cols = static_cast<int>(picture.getWidth());
  const cv::Mat1b grey(rows, cols, const_cast<unsigned char*>(picture.bitmap));
  cv::Mat1b ink;
  cv::subtract(cv::Scalar(255), grey, ink);
  const double texel_m = options.printed_picture.width_m / cols;
  *outline = RotatedRect(0.0, 0.0, 0.0, 0.5 * cols * texel_m, 0.5 * rows * texel_m);
  return Decal(cv::Mat1b(rows, cols, static_cast<unsigned char>(target.line_grey)), ink, texel_m,
               0.0, 0.0, 0.0, /*sharp_texels=*/true);
}

// Other sheets and objects on the surface, drawn from options.scene_seed.
void LayOutClutter(const LineTarget& target, const RenderOptions& options, SceneDressing* d) {
  std::mt19937_64 gen(SplitMix64(options.scene_seed ^ 0x636c7574746572ull));
  const double hw = 0.5 * target.board_width_m, hh = 0.5 * target.board_height_m;
  const double reach_x = hw + options.clutter_reach_m, reach_y = hh + options.clutter_reach_m;
  const Quad board_grown = RotatedRect(0.0, 0.0, 0.0, hw + kClutterGapM, hh + kClutterGapM);
  // A centre and angle for a rectangle of half sizes (half_x, half_y), or a disc of radius
  // half_x, clear of the board; false when none of the draws is.
  const auto place = [&](bool disc, double half_x, double half_y, double* cx, double* cy,
                         double* angle) {
    for (int draw = 0; draw < kClutterPlacementDraws; ++draw) {
      *cx = reach_x * (2.0 * Uniform(gen) - 1.0);
      *cy = reach_y * (2.0 * Uniform(gen) - 1.0);
      *angle = 2.0 * kPi * Uniform(gen);
      const bool near =
          disc ? DiscNearRect(*cx, *cy, half_x, hw, hh, kClutterGapM)
               : QuadsOverlap(RotatedRect(*cx, *cy, *angle, half_x, half_y), board_grown);
      if (!near) return true;
    }
    return false;
  };
  std::vector<Box> boxes;
  for (int i = 0; i < options.clutter_sheets; ++i) {
    const bool a4 = Uniform(gen) < 0.6;
    const double w = a4 ? 0.210 : 0.148, h = a4 ? 0.297 : 0.210;
    double cx = 0.0, cy = 0.0, angle = 0.0;
    if (!place(false, 0.5 * w, 0.5 * h, &cx, &cy, &angle)) continue;
    cv::Mat1b alpha;
    const cv::Mat1b grey = TextSheetPicture(w, h, gen, &alpha);
    d->sheets.emplace_back(grey, alpha, kClutterTexelM, cx, cy, angle);
    boxes.push_back(d->sheets.back().box());
  }
  for (int i = 0; i < options.clutter_objects; ++i) {
    BenchObject object;
    const double kind = Uniform(gen);
    if (kind < 0.4) {  // a bar: a ruler, a screwdriver, a pen
      object.half_x = 0.05 + 0.075 * Uniform(gen);
      object.half_y = 0.004 + 0.0135 * Uniform(gen);
    } else if (kind < 0.7) {  // a block: a phone, a box, a multimeter
      object.half_x = 0.03 + 0.045 * Uniform(gen);
      object.half_y = 0.02 + 0.025 * Uniform(gen);
    } else {  // a disc: a roll of tape, a cup
      object.disc = true;
      object.half_x = 0.02 + 0.03 * Uniform(gen);
      object.half_y = object.half_x;
    }
    object.grey = 15.0 + 55.0 * Uniform(gen);
    double angle = 0.0;
    if (!place(object.disc, object.half_x, object.half_y, &object.cx, &object.cy, &angle)) continue;
    object.cos = std::cos(angle);
    object.sin = std::sin(angle);
    object.box = Box::Of(object.Outline(), kCullMarginM);
    d->objects.push_back(object);
    boxes.push_back(object.box);
  }
  d->clutter = PlaneGrid(boxes);
}

std::shared_ptr<const SceneDressing> BuildDressing(const LineTarget& target,
                                                   const RenderOptions& options) {
  if (!NeedsDressing(options)) return nullptr;
  auto d = std::make_shared<SceneDressing>();
  d->paper_texture_grey = options.paper_texture_grey;
  d->paper_seed = SplitMix64(options.scene_seed ^ 0x7061706572ull);
  Quad picture_outline{};
  if (!options.printed_picture.empty()) {
    d->picture.push_back(PrintedPictureDecal(target, options, &picture_outline));
  }
  if (options.annotations) {
    d->annotations = LayOutAnnotations(target, options.annotation_grey,
                                       d->picture.empty() ? nullptr : &picture_outline);
  }
  LayOutClutter(target, options, d.get());
  d->shadow_darkness = options.shadow_darkness;
  d->shadow_x = options.shadow_offset_m * std::cos(options.shadow_angle_rad);
  d->shadow_y = options.shadow_offset_m * std::sin(options.shadow_angle_rad);
  d->shadow_half_w = 0.5 * target.board_width_m;
  d->shadow_half_h = 0.5 * target.board_height_m;
  d->shadow_softness = options.shadow_softness_m;
  return d;
}

// -------------------------------------------------------------------------------------------
// A frame's events on the plane (glares, and occluders with their shadows) and in the image
// (motion blur, JPEG).

// Cells of an occluder's texture (metres).
constexpr double kOccluderCellM = 0.005;

// The frame's glares and plane occluders, each culled by a box on the plane.
class PlaneEvents {
 public:
  explicit PlaneEvents(const FrameEffects& effects) {
    for (const Glare& glare : effects.glares) {
      const double reach = 4.0 * glare.sigma_m;
      glares_.push_back({&glare, Box{glare.x_m - reach, glare.y_m - reach, glare.x_m + reach,
                                     glare.y_m + reach}});
    }
    for (const PlaneOccluder& occluder : effects.plane_occluders) {
      Box box = OutlineBox(occluder);
      Box shadow = box;
      const double dx = occluder.shadow_offset_m * std::cos(occluder.shadow_angle_rad);
      const double dy = occluder.shadow_offset_m * std::sin(occluder.shadow_angle_rad);
      const double soft = occluder.shadow_softness_m;
      shadow = Box{box.min_x + dx - soft, box.min_y + dy - soft, box.max_x + dx + soft,
                   box.max_y + dy + soft};
      box = Box{box.min_x - kCullMarginM, box.min_y - kCullMarginM, box.max_x + kCullMarginM,
                box.max_y + kCullMarginM};
      occluders_.push_back({&occluder, box, shadow, dx, dy});
    }
  }

  bool empty() const { return glares_.empty() && occluders_.empty(); }

  // What the pixel whose centre sees the plane sample s shows, `under` being the scene there.
  double Apply(double under, const PlaneSample& s) const {
    double value = under;
    for (const OccluderBoxes& o : occluders_) {
      if (o.occluder->shadow_darkness <= 0.0 || !o.shadow.Contains(s.X, s.Y)) continue;
      const double w = std::max(o.occluder->shadow_softness_m, Footprint(s));
      const double d = o.occluder->SignedDistance(s.X - o.shadow_dx, s.Y - o.shadow_dy);
      value *= 1.0 - o.occluder->shadow_darkness * std::clamp(0.5 - d / w, 0.0, 1.0);
    }
    for (const GlareBox& g : glares_) {
      if (!g.box.Contains(s.X, s.Y)) continue;
      const double dx = s.X - g.glare->x_m, dy = s.Y - g.glare->y_m;
      value += g.glare->peak_grey *
               std::exp(-(dx * dx + dy * dy) / (2.0 * g.glare->sigma_m * g.glare->sigma_m));
    }
    for (const OccluderBoxes& o : occluders_) {
      if (!o.box.Contains(s.X, s.Y)) continue;
      const PlaneOccluder& occluder = *o.occluder;
      const double cover =
          std::clamp(0.5 - occluder.SignedDistance(s.X, s.Y) / Footprint(s), 0.0, 1.0);
      if (cover <= 0.0) continue;
      double grey = occluder.grey;
      if (occluder.texture_grey > 0.0) {
        grey +=
            occluder.texture_grey *
            ValueNoise(s.X, s.Y, kOccluderCellM, SplitMix64(occluder.texture_seed ^ 0x68616e64ull));
      }
      value += cover * (grey - value);
    }
    return value;
  }

 private:
  struct GlareBox {
    const Glare* glare;
    Box box;
  };
  struct OccluderBoxes {
    const PlaneOccluder* occluder;
    Box box, shadow;
    double shadow_dx, shadow_dy;
  };

  static Box OutlineBox(const PlaneOccluder& o) {
    Box box{std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
            std::numeric_limits<double>::lowest(), std::numeric_limits<double>::lowest()};
    const auto grow = [&box](double x, double y, double r) {
      box.min_x = std::min(box.min_x, x - r);
      box.min_y = std::min(box.min_y, y - r);
      box.max_x = std::max(box.max_x, x + r);
      box.max_y = std::max(box.max_y, y + r);
    };
    for (const PlaneOccluder::Capsule& c : o.capsules) {
      grow(c.x1_m, c.y1_m, c.radius_m);
      grow(c.x2_m, c.y2_m, c.radius_m);
    }
    for (const PlaneOccluder::Ellipse& e : o.ellipses) {
      grow(e.x_m, e.y_m, std::max(e.semi_a_m, e.semi_b_m));
    }
    return box;
  }

  std::vector<GlareBox> glares_;
  std::vector<OccluderBoxes> occluders_;
};

// The image integrated along a straight path of length_px in direction angle_rad: a kernel of
// the segment's samples, each spread bilinearly over the four pixels around it.
void ApplyMotionBlur(double length_px, double angle_rad, cv::Mat1f* image) {
  if (length_px <= 0.0) return;
  const int half = static_cast<int>(std::ceil(0.5 * length_px)) + 1;
  cv::Mat1f kernel = cv::Mat1f::zeros(2 * half + 1, 2 * half + 1);
  const int samples = std::max(2, static_cast<int>(std::ceil(8.0 * length_px)));
  const double c = std::cos(angle_rad), s = std::sin(angle_rad);
  for (int i = 0; i < samples; ++i) {
    const double t = length_px * ((i + 0.5) / samples - 0.5);
    const double x = half + t * c, y = half + t * s;
    const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
    const double ax = x - x0, ay = y - y0;
    kernel(y0, x0) += static_cast<float>((1.0 - ax) * (1.0 - ay));
    kernel(y0, x0 + 1) += static_cast<float>(ax * (1.0 - ay));
    kernel(y0 + 1, x0) += static_cast<float>((1.0 - ax) * ay);
    kernel(y0 + 1, x0 + 1) += static_cast<float>(ax * ay);
  }
  kernel /= static_cast<float>(cv::sum(kernel)[0]);
  cv::filter2D(*image, *image, -1, kernel, cv::Point(-1, -1), 0.0, cv::BORDER_REFLECT);
}

// The 8-bit frame compressed as a JPEG of `quality` and decoded again.
void CompressAsJpeg(int quality, vpImage<unsigned char>* image) {
  if (quality <= 0) return;
  const cv::Mat view(static_cast<int>(image->getHeight()), static_cast<int>(image->getWidth()),
                     CV_8U, image->bitmap);
  std::vector<unsigned char> bytes;
  if (!cv::imencode(".jpg", view, bytes, {cv::IMWRITE_JPEG_QUALITY, quality})) {
    throw std::runtime_error("the frame could not be compressed as a JPEG");
  }
  const cv::Mat decoded = cv::imdecode(bytes, cv::IMREAD_GRAYSCALE);
  if (decoded.size() != view.size() || decoded.type() != CV_8U) {
    throw std::runtime_error("the frame's JPEG could not be decoded");
  }
  decoded.copyTo(view);
}

}  // namespace

// -------------------------------------------------------------------------------------------
// Options.

void RenderOptions::Check() const {
  RequireOption(InRange(width, 16, 8192), "RenderOptions::width", width, "16 <= width <= 8192");
  RequireOption(InRange(height, 16, 8192), "RenderOptions::height", height, "16 <= height <= 8192");
  CheckPerspectiveCamera(camera, "RenderOptions::camera");
  CheckInvertibleOver(camera, width, height, "RenderOptions::camera");
  RequireOption(InRange(noise_sigma, 0.0, 100.0), "RenderOptions::noise_sigma", noise_sigma,
                "0 <= noise_sigma <= 100");
  RequireOption(InRange(blur_sigma_px, 0.0, 20.0), "RenderOptions::blur_sigma_px", blur_sigma_px,
                "0 <= blur_sigma_px <= 20");
  RequireOption(InRange(illumination_gradient, 0.0, 0.9), "RenderOptions::illumination_gradient",
                illumination_gradient, "0 <= illumination_gradient <= 0.9");
  RequireOption(std::isfinite(gradient_angle_rad), "RenderOptions::gradient_angle_rad",
                gradient_angle_rad, "gradient_angle_rad is finite");
  RequireOption(InRange(background_grey, 0, 255), "RenderOptions::background_grey", background_grey,
                "0 <= background_grey <= 255");
  RequireOption(InRange(supersample, 1, 8), "RenderOptions::supersample", supersample,
                "1 <= supersample <= 8");
  RequireOption(background_texel_m > 0.0 && background_texel_m <= 1.0,
                "RenderOptions::background_texel_m", background_texel_m,
                "0 < background_texel_m <= 1");
  RequireOption(InRange(vignetting, 0.0, 0.9), "RenderOptions::vignetting", vignetting,
                "0 <= vignetting <= 0.9");
  RequireOption(InRange(hot_spot_gain, 0.0, 2.0), "RenderOptions::hot_spot_gain", hot_spot_gain,
                "0 <= hot_spot_gain <= 2");
  RequireOption(InRange(hot_spot_u, -2.0, 3.0), "RenderOptions::hot_spot_u", hot_spot_u,
                "-2 <= hot_spot_u <= 3");
  RequireOption(InRange(hot_spot_v, -2.0, 3.0), "RenderOptions::hot_spot_v", hot_spot_v,
                "-2 <= hot_spot_v <= 3");
  RequireOption(InRange(hot_spot_sigma, 0.01, 10.0), "RenderOptions::hot_spot_sigma",
                hot_spot_sigma, "0.01 <= hot_spot_sigma <= 10");
  RequireOption(InRange(shadow_darkness, 0.0, 0.95), "RenderOptions::shadow_darkness",
                shadow_darkness, "0 <= shadow_darkness <= 0.95");
  RequireOption(InRange(shadow_offset_m, 0.0, 0.1), "RenderOptions::shadow_offset_m",
                shadow_offset_m, "0 <= shadow_offset_m <= 0.1");
  RequireOption(std::isfinite(shadow_angle_rad), "RenderOptions::shadow_angle_rad",
                shadow_angle_rad, "shadow_angle_rad is finite");
  RequireOption(InRange(shadow_softness_m, 0.0, 0.05), "RenderOptions::shadow_softness_m",
                shadow_softness_m, "0 <= shadow_softness_m <= 0.05");
  RequireOption(InRange(paper_texture_grey, 0.0, 20.0), "RenderOptions::paper_texture_grey",
                paper_texture_grey, "0 <= paper_texture_grey <= 20");
  RequireOption(InRange(annotation_grey, 0, 255), "RenderOptions::annotation_grey", annotation_grey,
                "0 <= annotation_grey <= 255");
  RequireOption(InRange(clutter_sheets, 0, 10), "RenderOptions::clutter_sheets", clutter_sheets,
                "0 <= clutter_sheets <= 10");
  RequireOption(InRange(clutter_objects, 0, 50), "RenderOptions::clutter_objects", clutter_objects,
                "0 <= clutter_objects <= 50");
  RequireOption(clutter_reach_m > 0.0 && clutter_reach_m <= 10.0, "RenderOptions::clutter_reach_m",
                clutter_reach_m, "0 < clutter_reach_m <= 10");
  if (!printed_picture.empty()) {
    RequireOption(printed_picture.width_m > 0.0 && printed_picture.width_m <= 100.0,
                  "RenderOptions::printed_picture.width_m", printed_picture.width_m,
                  "0 < width_m <= 100 with a picture");
  }
}

bool Occluder::Contains(double u, double v) const {
  if (shape == Shape::kRectangle) {
    return std::fabs(u - centre_u_px) <= half_width_px &&
           std::fabs(v - centre_v_px) <= half_height_px;
  }
  return std::hypot(u - centre_u_px, v - centre_v_px) <= half_width_px;
}

void Occluder::Check() const {
  RequireOption(std::isfinite(centre_u_px), "Occluder::centre_u_px", centre_u_px,
                "centre_u_px is finite");
  RequireOption(std::isfinite(centre_v_px), "Occluder::centre_v_px", centre_v_px,
                "centre_v_px is finite");
  RequireOption(half_width_px > 0.0 && half_width_px < 1e6, "Occluder::half_width_px",
                half_width_px, "0 < half_width_px < 1e6");
  if (shape == Shape::kRectangle) {
    RequireOption(half_height_px > 0.0 && half_height_px < 1e6, "Occluder::half_height_px",
                  half_height_px, "0 < half_height_px < 1e6");
  }
  RequireOption(InRange(grey, 0, 255), "Occluder::grey", grey, "0 <= grey <= 255");
}

double PlaneOccluder::SignedDistance(double X, double Y) const {
  double distance = std::numeric_limits<double>::infinity();
  for (const Capsule& c : capsules) {
    const double dx = c.x2_m - c.x1_m, dy = c.y2_m - c.y1_m;
    const double length2 = dx * dx + dy * dy;
    const double t = length2 > 0.0
                         ? std::clamp(((X - c.x1_m) * dx + (Y - c.y1_m) * dy) / length2, 0.0, 1.0)
                         : 0.0;
    distance =
        std::min(distance, std::hypot(X - c.x1_m - t * dx, Y - c.y1_m - t * dy) - c.radius_m);
  }
  for (const Ellipse& e : ellipses) {
    // f = (a'/A)^2 + (b'/B)^2 - 1 over its gradient's length: the distance to first order.
    const double cs = std::cos(e.angle_rad), sn = std::sin(e.angle_rad);
    const double a = cs * (X - e.x_m) + sn * (Y - e.y_m), b = -sn * (X - e.x_m) + cs * (Y - e.y_m);
    const double ia = 1.0 / (e.semi_a_m * e.semi_a_m), ib = 1.0 / (e.semi_b_m * e.semi_b_m);
    const double f = a * a * ia + b * b * ib - 1.0;
    const double gradient = 2.0 * std::hypot(a * ia, b * ib);
    distance =
        std::min(distance, gradient > 0.0 ? f / gradient : -std::min(e.semi_a_m, e.semi_b_m));
  }
  return distance;
}

void PlaneOccluder::Check() const {
  RequireOption(!capsules.empty() || !ellipses.empty(), "PlaneOccluder::capsules, ellipses", "none",
                "at least one capsule or ellipse");
  for (const Capsule& c : capsules) {
    RequireOption(std::isfinite(c.x1_m) && std::isfinite(c.y1_m) && std::isfinite(c.x2_m) &&
                      std::isfinite(c.y2_m),
                  "PlaneOccluder::Capsule::x1_m, y1_m, x2_m, y2_m", "not finite", "finite");
    RequireOption(c.radius_m > 0.0 && c.radius_m <= 1.0, "PlaneOccluder::Capsule::radius_m",
                  c.radius_m, "0 < radius_m <= 1");
  }
  for (const Ellipse& e : ellipses) {
    RequireOption(std::isfinite(e.x_m) && std::isfinite(e.y_m) && std::isfinite(e.angle_rad),
                  "PlaneOccluder::Ellipse::x_m, y_m, angle_rad", "not finite", "finite");
    RequireOption(e.semi_a_m > 0.0 && e.semi_a_m <= 1.0 && e.semi_b_m > 0.0 && e.semi_b_m <= 1.0,
                  "PlaneOccluder::Ellipse::semi_a_m, semi_b_m",
                  std::to_string(e.semi_a_m) + ", " + std::to_string(e.semi_b_m), "both in (0, 1]");
  }
  RequireOption(InRange(grey, 0, 255), "PlaneOccluder::grey", grey, "0 <= grey <= 255");
  RequireOption(InRange(texture_grey, 0.0, 100.0), "PlaneOccluder::texture_grey", texture_grey,
                "0 <= texture_grey <= 100");
  RequireOption(InRange(shadow_darkness, 0.0, 0.95), "PlaneOccluder::shadow_darkness",
                shadow_darkness, "0 <= shadow_darkness <= 0.95");
  RequireOption(InRange(shadow_offset_m, 0.0, 1.0), "PlaneOccluder::shadow_offset_m",
                shadow_offset_m, "0 <= shadow_offset_m <= 1");
  RequireOption(std::isfinite(shadow_angle_rad), "PlaneOccluder::shadow_angle_rad",
                shadow_angle_rad, "shadow_angle_rad is finite");
  RequireOption(InRange(shadow_softness_m, 0.0, 1.0), "PlaneOccluder::shadow_softness_m",
                shadow_softness_m, "0 <= shadow_softness_m <= 1");
}

void Glare::Check() const {
  RequireOption(std::isfinite(x_m) && std::isfinite(y_m), "Glare::x_m, y_m", "not finite",
                "finite");
  RequireOption(sigma_m > 0.0 && sigma_m <= 1.0, "Glare::sigma_m", sigma_m, "0 < sigma_m <= 1");
  RequireOption(InRange(peak_grey, 0.0, 2000.0), "Glare::peak_grey", peak_grey,
                "0 <= peak_grey <= 2000");
}

void FrameEffects::Check() const {
  RequireOption(InRange(gain, 0.0, 10.0), "FrameEffects::gain", gain, "0 <= gain <= 10");
  RequireOption(InRange(offset, -255.0, 255.0), "FrameEffects::offset", offset,
                "-255 <= offset <= 255");
  for (const Occluder& occluder : occluders) occluder.Check();
  RequireOption(noise_sigma < 0.0 || noise_sigma <= 100.0, "FrameEffects::noise_sigma", noise_sigma,
                "noise_sigma <= 100 (negative: the renderer's)");
  RequireOption(blur_sigma_px < 0.0 || blur_sigma_px <= 20.0, "FrameEffects::blur_sigma_px",
                blur_sigma_px, "blur_sigma_px <= 20 (negative: the renderer's)");
  for (const PlaneOccluder& occluder : plane_occluders) occluder.Check();
  for (const Glare& glare : glares) glare.Check();
  RequireOption(InRange(motion_blur_px, 0.0, 200.0), "FrameEffects::motion_blur_px", motion_blur_px,
                "0 <= motion_blur_px <= 200");
  RequireOption(std::isfinite(motion_blur_angle_rad), "FrameEffects::motion_blur_angle_rad",
                motion_blur_angle_rad, "motion_blur_angle_rad is finite");
  RequireOption(InRange(jpeg_quality, 0, 100), "FrameEffects::jpeg_quality", jpeg_quality,
                "0 <= jpeg_quality <= 100");
}

void PoseSampling::Check() const {
  RequireOption(min_distance_m > 0.0, "PoseSampling::min_distance_m", min_distance_m,
                "min_distance_m > 0");
  RequireOption(max_distance_m >= min_distance_m && std::isfinite(max_distance_m),
                "PoseSampling::max_distance_m", max_distance_m, "min_distance_m <= max_distance_m");
  RequireOption(InRange(max_tilt_deg, 0.0, 80.0), "PoseSampling::max_tilt_deg", max_tilt_deg,
                "0 <= max_tilt_deg <= 80");
  RequireOption(InRange(min_tilt_deg, 0.0, max_tilt_deg), "PoseSampling::min_tilt_deg",
                min_tilt_deg, "0 <= min_tilt_deg <= max_tilt_deg");
  RequireOption(max_offset_m >= 0.0 && std::isfinite(max_offset_m), "PoseSampling::max_offset_m",
                max_offset_m, "max_offset_m >= 0");
  RequireOption(min_visible_length_px >= 0.0 && std::isfinite(min_visible_length_px),
                "PoseSampling::min_visible_length_px", min_visible_length_px,
                "min_visible_length_px >= 0");
  RequireOption(InRange(crossings_margin_px, 0.0, 1000.0), "PoseSampling::crossings_margin_px",
                crossings_margin_px, "0 <= crossings_margin_px <= 1000");
}

// -------------------------------------------------------------------------------------------
// Renderer.

SceneRenderer::SceneRenderer(LineTarget target, RenderOptions options)
    : target_(std::move(target)), options_(std::move(options)) {
  target_.Check();
  options_.Check();
  if (options_.background != nullptr) {
    background_ = options_.background;
  } else {
    background_ = std::make_shared<vpImage<unsigned char>>();
  }
  dressing_ = BuildDressing(target_, options_);
  const std::size_t n = static_cast<std::size_t>(options_.width) * options_.height;
  ray_x_.resize(n);
  ray_y_.resize(n);
  for (int v = 0; v < options_.height; ++v) {
    for (int u = 0; u < options_.width; ++u) {
      const Point2d ideal = options_.camera.Normalised(u, v);
      const double x = ideal.u, y = ideal.v;
      const std::size_t i = static_cast<std::size_t>(v) * options_.width + u;
      ray_x_[i] = static_cast<float>(x);
      ray_y_[i] = static_cast<float>(y);
    }
  }
}

RenderedFrame SceneRenderer::Render(const vpHomogeneousMatrix& cMo,
                                    std::uint64_t noise_seed) const {
  return Render(cMo, noise_seed, FrameEffects());
}

RenderedFrame SceneRenderer::Render(const vpHomogeneousMatrix& cMo, std::uint64_t noise_seed,
                                    const FrameEffects& effects) const {
  effects.Check();
  const PlaneProjector projector(cMo, options_.camera);
  PixelCoverage coverage(BuildRegions(target_), options_.supersample);
  const BackgroundShade background(*background_, options_.background_texel_m,
                                   options_.background_grey);
  const double board = target_.board_grey, line = target_.line_grey;
  const SceneDressing* dressing = dressing_.get();
  const PlaneEvents events(effects);

  cv::Mat1f radiance(options_.height, options_.width);
  for (int v = 0; v < options_.height; ++v) {
    float* row = radiance.ptr<float>(v);
    const std::size_t offset = static_cast<std::size_t>(v) * options_.width;
    for (int u = 0; u < options_.width; ++u) {
      PlaneSample s;
      if (!projector.Sample(u, v, ray_x_[offset + u], ray_y_[offset + u], &s)) {
        row[u] = static_cast<float>(options_.background_grey);
        continue;
      }
      const Coverage c = coverage.Of(s);
      double around = c.board < 1.0 ? background.At(s.X, s.Y) : 0.0;
      double paper = board;
      if (dressing != nullptr) {
        const double footprint_m = Footprint(s);
        if (c.board < 1.0) around = dressing->Surface(around, s, footprint_m);
        if (c.board > 0.0) paper = dressing->Paper(board, s, footprint_m);
      }
      const double seen = around * (1.0 - c.board) + paper * (c.board - c.dark) + line * c.dark;
      row[u] = static_cast<float>(events.empty() ? seen : events.Apply(seen, s));
    }
  }
  PaintOccluders(effects.occluders, &radiance);
  ApplyIllumination(options_.illumination_gradient, options_.gradient_angle_rad, &radiance);
  ApplyLightFalloff(options_, &radiance);
  ApplyGainOffset(effects.gain, effects.offset, &radiance);
  ApplyMotionBlur(effects.motion_blur_px, effects.motion_blur_angle_rad, &radiance);
  const double blur = effects.blur_sigma_px >= 0.0 ? effects.blur_sigma_px : options_.blur_sigma_px;
  if (blur > 0.0) {
    cv::GaussianBlur(radiance, radiance, cv::Size(), blur, blur, cv::BORDER_REFLECT);
  }
  AddNoise(effects.noise_sigma >= 0.0 ? effects.noise_sigma : options_.noise_sigma, noise_seed,
           &radiance);

  RenderedFrame frame;
  frame.image.resize(static_cast<unsigned>(options_.height), static_cast<unsigned>(options_.width));
  cv::Mat out(options_.height, options_.width, CV_8U, frame.image.bitmap);
  radiance.convertTo(out, CV_8U);  // rounds and saturates to [0, 255]
  CompressAsJpeg(effects.jpeg_quality, &frame.image);
  frame.cMo = cMo;
  frame.truth = Truth(cMo, effects);
  return frame;
}

std::vector<TruthLine> SceneRenderer::Truth(const vpHomogeneousMatrix& cMo) const {
  return Truth(cMo, FrameEffects());
}

std::vector<TruthLine> SceneRenderer::Truth(const vpHomogeneousMatrix& cMo,
                                            const FrameEffects& effects) const {
  std::vector<TruthLine> truth;
  truth.reserve(target_.lines.size());
  for (std::size_t i = 0; i < target_.lines.size(); ++i) {
    truth.push_back(LineTruth(target_.lines[i], static_cast<int>(i), cMo, options_, effects));
  }
  return truth;
}

// -------------------------------------------------------------------------------------------
// Lens helpers and pose sampling.

std::vector<StripeCrossing> StripeCrossings(const LineTarget& target) {
  const double min_sin = std::sin(kPi / 180.0);
  std::vector<StripeCrossing> crossings;
  for (std::size_t a = 0; a < target.lines.size(); ++a) {
    for (std::size_t b = a + 1; b < target.lines.size(); ++b) {
      const TargetLine& la = target.lines[a];
      const TargetLine& lb = target.lines[b];
      const double dax = la.x2_m - la.x1_m, day = la.y2_m - la.y1_m;
      const double dbx = lb.x2_m - lb.x1_m, dby = lb.y2_m - lb.y1_m;
      const double cross = dax * dby - day * dbx;
      if (std::fabs(cross) <= min_sin * std::hypot(dax, day) * std::hypot(dbx, dby)) continue;
      // la.1 + s da = lb.1 + t db with s, t in [0, 1].
      const double ex = lb.x1_m - la.x1_m, ey = lb.y1_m - la.y1_m;
      const double sa = (ex * dby - ey * dbx) / cross, tb = (ex * day - ey * dax) / cross;
      if (sa < 0.0 || sa > 1.0 || tb < 0.0 || tb > 1.0) continue;
      // Each stripe's sides: n . P = offset +- width / 2, n its unit normal.
      const double na = std::hypot(dax, day), nb = std::hypot(dbx, dby);
      const double ax = -day / na, ay = dax / na, bx = -dby / nb, by = dbx / nb;
      const double oa = ax * la.x1_m + ay * la.y1_m, ob = bx * lb.x1_m + by * lb.y1_m;
      const double det = ax * by - ay * bx;
      StripeCrossing crossing;
      crossing.line_a = static_cast<int>(a);
      crossing.line_b = static_cast<int>(b);
      const double signs[4][2] = {{1.0, 1.0}, {1.0, -1.0}, {-1.0, -1.0}, {-1.0, 1.0}};
      for (int i = 0; i < 4; ++i) {
        const double ca = oa + signs[i][0] * 0.5 * la.width_m;
        const double cb = ob + signs[i][1] * 0.5 * lb.width_m;
        crossing.corners_m[i] = {(ca * by - cb * ay) / det, (ax * cb - bx * ca) / det};
      }
      crossings.push_back(crossing);
    }
  }
  return crossings;
}

namespace {

bool CornersInView(const RenderOptions& options, const vpHomogeneousMatrix& cMo,
                   const std::vector<StripeCrossing>& crossings, double margin_px) {
  for (const StripeCrossing& crossing : crossings) {
    for (const auto& corner : crossing.corners_m) {
      const Vec3 p = ToCamera(cMo, corner[0], corner[1]);
      if (!(p.z > kMinDepthM)) return false;
      const Point2d pixel = options.camera.Pixel(p.x / p.z, p.y / p.z);
      if (!(pixel.u >= margin_px && pixel.u <= options.width - 1 - margin_px &&
            pixel.v >= margin_px && pixel.v <= options.height - 1 - margin_px)) {
        return false;
      }
    }
  }
  return true;
}

}  // namespace

bool CrossingsInView(const SceneRenderer& renderer, const vpHomogeneousMatrix& cMo,
                     double margin_px) {
  return CornersInView(renderer.options(), cMo, StripeCrossings(renderer.target()), margin_px);
}

vpHomogeneousMatrix SamplePose(const SceneRenderer& renderer, const PoseSampling& sampling,
                               std::uint64_t* state) {
  sampling.Check();
  const std::vector<StripeCrossing> crossings = sampling.crossings_in_view
                                                    ? StripeCrossings(renderer.target())
                                                    : std::vector<StripeCrossing>();
  std::mt19937_64 gen(*state);
  for (int attempt = 0; attempt < 1000; ++attempt) {
    const vpHomogeneousMatrix cMo = DrawPose(sampling, gen);
    if ((sampling.min_visible_length_px <= 0.0 ||
         LongEnough(renderer.Truth(cMo), sampling.min_visible_length_px)) &&
        (!sampling.crossings_in_view ||
         CornersInView(renderer.options(), cMo, crossings, sampling.crossings_margin_px))) {
      *state = gen();
      return cMo;
    }
  }
  std::ostringstream message;
  message << "SamplePose: none of 1000 poses shows every line of target '" << renderer.target().name
          << "' over min_visible_length_px = " << sampling.min_visible_length_px << " px";
  if (sampling.crossings_in_view) {
    message << " with every crossing square crossings_margin_px = " << sampling.crossings_margin_px
            << " px inside the image";
  }
  throw std::runtime_error(message.str());
}

}  // namespace oal
