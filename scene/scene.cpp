#include "scene/scene.h"

#include <visp3/core/vpPixelMeterConversion.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "detector/options.h"
#include "scene/geometry.h"

namespace oal {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Points closer to the camera plane than this are treated as behind the camera (metres).
constexpr double kMinDepthM = 1e-6;
// Rays meeting the board plane farther than this see background_grey (metres).
constexpr double kMaxDepthM = 1e6;
// Size on the board plane of one texel of the background image (metres).
constexpr double kBackgroundTexelM = 0.002;
// Samples of a target line used to find its visible part, and to fit its distorted image.
constexpr int kVisibilitySamples = 1000;
constexpr int kFitSamples = 400;

bool InRange(double value, double lo, double hi) {
  return value >= lo && value <= hi;
}

double Kdu(const vpCameraParameters& camera) {
  return camera.get_projModel() == vpCameraParameters::perspectiveProjWithDistortion
             ? camera.get_kdu()
             : 0.0;
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
bool IdealLineOf(const vpCameraParameters& camera, const Vec3& a, const Vec3& b, LineParams* out) {
  const Vec3 n = Cross(a, b);
  const double A = n.x / camera.get_px(), B = n.y / camera.get_py();
  const double C = n.z - A * camera.get_u0() - B * camera.get_v0();
  const double norm = std::hypot(A, B);
  if (!(norm > 1e-15 * std::fabs(C))) return false;
  *out = Normalized(-C / norm, std::atan2(B, A));
  return true;
}

Point2d IdealPixel(const vpCameraParameters& camera, const Vec3& p) {
  return {camera.get_u0() + camera.get_px() * p.x / p.z,
          camera.get_v0() + camera.get_py() * p.y / p.z};
}

// Distorted normalised radius r with r (1 + k r^2) = rho (Newton; monotone convergence from
// r = rho since the cubic is convex for k > 0 and concave for k < 0). NaN when unreachable.
double DistortedRadius(double k, double rho) {
  if (k < 0.0) {
    const double r_turn = 1.0 / std::sqrt(-3.0 * k);  // where d(rho)/dr = 0
    if (rho > r_turn * (2.0 / 3.0)) return kNaN;
  }
  double r = rho;
  for (int i = 0; i < 200; ++i) {
    const double step = (k * r * r * r + r - rho) / (3.0 * k * r * r + 1.0);
    r -= step;
    if (std::fabs(step) <= 1e-16 * (1.0 + r)) break;
  }
  return r;
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
    *pixel = DistortedPixel(options_.camera, p.x / p.z, p.y / p.z);
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
double ApparentWidth(const TargetLine& line, const vpHomogeneousMatrix& cMo,
                     const vpCameraParameters& camera, double t) {
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
                    const RenderOptions& options, const std::vector<Occluder>& occluders) {
  TruthLine truth;
  truth.index = index;
  const Vec3 c1 = ToCamera(cMo, line.x1_m, line.y1_m);
  const Vec3 c2 = ToCamera(cMo, line.x2_m, line.y2_m);
  if (!IdealLineOf(options.camera, c1, c2, &truth.ideal)) return truth;
  const SegmentView view(options, c1, c2);
  double t_a = 0.0, t_b = 0.0;
  if (!VisibleRange(view, &t_a, &t_b)) return truth;

  std::vector<Point2d> points;
  points.reserve(kFitSamples);
  for (int i = 0; i < kFitSamples; ++i) {
    Point2d p;
    if (view.Inside(t_a + (t_b - t_a) * i / (kFitSamples - 1.0), &p)) points.push_back(p);
  }
  if (points.size() < 2) return truth;
  truth.visible = true;
  truth.distorted_fit = FitLine(points);
  view.Inside(t_a, &truth.end_a);
  view.Inside(t_b, &truth.end_b);
  truth.visible_length_px =
      std::hypot(truth.end_b.u - truth.end_a.u, truth.end_b.v - truth.end_a.v);
  truth.width_px = ApparentWidth(line, cMo, options.camera, 0.5 * (t_a + t_b));
  if (!occluders.empty()) {
    const auto hidden = std::count_if(points.begin(), points.end(), [&](const Point2d& p) {
      return std::any_of(occluders.begin(), occluders.end(),
                         [&](const Occluder& o) { return o.Contains(p.u, p.v); });
    });
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
  PlaneProjector(const vpHomogeneousMatrix& cMo, const vpCameraParameters& camera)
      : u0_(camera.get_u0()),
        v0_(camera.get_v0()),
        inv_px_(1.0 / camera.get_px()),
        inv_py_(1.0 / camera.get_py()),
        k_(Kdu(camera)) {
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
    // d(x, y)/d(u, v) of x = du (1 + k r^2), du = (u - u0) / px, likewise y.
    const double du = (u - u0_) * inv_px_, dv = (v - v0_) * inv_py_;
    const double f = 1.0 + k_ * (du * du + dv * dv);
    const double cross = 2.0 * k_ * du * dv;
    const double xu = (f + 2.0 * k_ * du * du) * inv_px_, xv = cross * inv_py_;
    const double yu = cross * inv_px_, yv = (f + 2.0 * k_ * dv * dv) * inv_py_;
    s->Xu = Xx * xu + Xy * yu;
    s->Xv = Xx * xv + Xy * yv;
    s->Yu = Yx * xu + Yy * yu;
    s->Yv = Yx * xv + Yy * yv;
    return true;
  }

 private:
  double u0_, v0_, inv_px_, inv_py_, k_;
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
  BackgroundShade(const vpImage<unsigned char>& image, double grey) : image_(image), grey_(grey) {}

  double At(double X, double Y) const {
    if (image_.getSize() == 0) return grey_;
    const double fx = X / kBackgroundTexelM, fy = Y / kBackgroundTexelM;
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

// SplitMix64, to spread nearby seeds over the generator's state space.
std::uint64_t Mix(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

void AddNoise(double sigma, std::uint64_t seed, cv::Mat1f* image) {
  if (sigma <= 0.0) return;
  cv::RNG rng(Mix(seed));
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
  const double tilt = sampling.max_tilt_deg * deg * Uniform(gen);
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

}  // namespace

// -------------------------------------------------------------------------------------------
// Targets.

void LineTarget::Check() const {
  RequireOption(board_width_m > 0.0, "LineTarget::board_width_m", board_width_m,
                "board_width_m > 0");
  RequireOption(board_height_m > 0.0, "LineTarget::board_height_m", board_height_m,
                "board_height_m > 0");
  RequireOption(board_grey >= 0 && board_grey <= 255, "LineTarget::board_grey", board_grey,
                "0 <= board_grey <= 255");
  RequireOption(line_grey >= 0 && line_grey <= 255, "LineTarget::line_grey", line_grey,
                "0 <= line_grey <= 255");
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const TargetLine& line = lines[i];
    const std::string prefix = "LineTarget::lines[" + std::to_string(i) + "].";
    for (const auto& [field, value] : {std::pair<const char*, double>{"x1_m", line.x1_m},
                                       {"y1_m", line.y1_m},
                                       {"x2_m", line.x2_m},
                                       {"y2_m", line.y2_m}}) {
      RequireOption(std::isfinite(value), prefix + field, value, std::string(field) + " is finite");
    }
    RequireOption(line.width_m > 0.0, prefix + "width_m", line.width_m, "width_m > 0");
    const double length = std::hypot(line.x2_m - line.x1_m, line.y2_m - line.y1_m);
    RequireOption(length > 0.0, prefix + "length", length, "the two ends differ");
  }
}

LineTarget TwoLineTarget() {
  LineTarget target;
  target.name = "two-line";
  target.lines = {TargetLine{-0.06, -1.0, -0.06, 1.0, 0.02},
                  TargetLine{0.06, -1.0, 0.06, 1.0, 0.02}};
  return target;
}

LineTarget FourLineTarget() {
  LineTarget target;
  target.name = "four-line-board";
  // Lines 1 and 3 vertical (0.18 m apart), lines 2 and 4 horizontal (0.13 m apart); the
  // widths 30, 15, 20 and 17.5 mm differ, line 1 is the widest.
  target.lines = {
      TargetLine{-0.08, -1.0, -0.08, 1.0, 0.03}, TargetLine{-1.0, -0.07, 1.0, -0.07, 0.015},
      TargetLine{0.10, -1.0, 0.10, 1.0, 0.02}, TargetLine{-1.0, 0.06, 1.0, 0.06, 0.0175}};
  return target;
}

namespace {

// A '#' on one landscape sheet (config/four-line-a3.yaml explains the choices): the stripes
// run from margin to margin, the four crossings form a half_x x half_y rectangle (times 2)
// centred on the sheet, lines 1 and 3 at x = -+half_x, lines 2 and 4 at y = -+half_y.
LineTarget SheetTarget(const std::string& name, double sheet_width_m, double sheet_height_m,
                       double margin_m, double half_x_m, double half_y_m,
                       const std::array<double, 4>& widths_m) {
  LineTarget target;
  target.name = name;
  target.board_width_m = sheet_width_m;
  target.board_height_m = sheet_height_m;
  const double x_end = 0.5 * sheet_width_m - margin_m, y_end = 0.5 * sheet_height_m - margin_m;
  target.lines = {TargetLine{-half_x_m, -y_end, -half_x_m, y_end, widths_m[0]},
                  TargetLine{-x_end, -half_y_m, x_end, -half_y_m, widths_m[1]},
                  TargetLine{half_x_m, -y_end, half_x_m, y_end, widths_m[2]},
                  TargetLine{-x_end, half_y_m, x_end, half_y_m, widths_m[3]}};
  return target;
}

}  // namespace

LineTarget FourLineA3Target() {
  return SheetTarget("four-line-a3", 0.420, 0.297, 0.010, 0.090, 0.062,
                     {0.024, 0.012, 0.016, 0.014});
}

LineTarget FourLineA4Target() {
  return SheetTarget("four-line-a4", 0.297, 0.210, 0.010, 0.063, 0.043,
                     {0.018, 0.009, 0.012, 0.0105});
}

LineTarget FourLineLetterTarget() {
  return SheetTarget("four-line-letter", 0.2794, 0.2159, 0.010, 0.0594, 0.0441,
                     {0.018, 0.009, 0.012, 0.0105});
}

const std::vector<std::string>& TargetNames() {
  static const std::vector<std::string> names = {"four-line-a3", "four-line-a4", "four-line-letter",
                                                 "four-line-board", "two-line"};
  return names;
}

LineTarget TargetByName(const std::string& name) {
  if (name == "two-line") return TwoLineTarget();
  if (name == "four-line-board" || name == "four-line") return FourLineTarget();
  if (name == "four-line-a3") return FourLineA3Target();
  if (name == "four-line-a4") return FourLineA4Target();
  if (name == "four-line-letter") return FourLineLetterTarget();
  std::string list;
  for (const std::string& known : TargetNames()) list += (list.empty() ? "" : ", ") + known;
  throw std::invalid_argument("target '" + name + "' is not one of: " + list);
}

// -------------------------------------------------------------------------------------------
// Options.

void RenderOptions::Check() const {
  RequireOption(InRange(width, 16, 8192), "RenderOptions::width", width, "16 <= width <= 8192");
  RequireOption(InRange(height, 16, 8192), "RenderOptions::height", height, "16 <= height <= 8192");
  const auto model = camera.get_projModel();
  RequireOption(model == vpCameraParameters::perspectiveProjWithoutDistortion ||
                    model == vpCameraParameters::perspectiveProjWithDistortion,
                "RenderOptions::camera.projModel", static_cast<int>(model),
                "perspective projection with or without (kdu) distortion");
  RequireOption(camera.get_px() > 0.0 && std::isfinite(camera.get_px()), "RenderOptions::camera.px",
                camera.get_px(), "px > 0");
  RequireOption(camera.get_py() > 0.0 && std::isfinite(camera.get_py()), "RenderOptions::camera.py",
                camera.get_py(), "py > 0");
  RequireOption(std::isfinite(camera.get_u0()), "RenderOptions::camera.u0", camera.get_u0(),
                "u0 is finite");
  RequireOption(std::isfinite(camera.get_v0()), "RenderOptions::camera.v0", camera.get_v0(),
                "v0 is finite");
  // The pixel -> ray map must not fold over inside the image: 1 + 3 kdu r^2 > 0 at the
  // farthest corner (the radial derivative of r (1 + kdu r^2)).
  const double du = std::max(std::fabs(camera.get_u0()), std::fabs(width - 1 - camera.get_u0()));
  const double dv = std::max(std::fabs(camera.get_v0()), std::fabs(height - 1 - camera.get_v0()));
  const double r2 =
      du * du / (camera.get_px() * camera.get_px()) + dv * dv / (camera.get_py() * camera.get_py());
  RequireOption(std::isfinite(Kdu(camera)) && 1.0 + 3.0 * Kdu(camera) * r2 > 0.0,
                "RenderOptions::camera.kdu", Kdu(camera),
                "1 + 3 kdu r^2 > 0 at the image corners (the lens model is invertible)");
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

void FrameEffects::Check() const {
  RequireOption(InRange(gain, 0.0, 10.0), "FrameEffects::gain", gain, "0 <= gain <= 10");
  RequireOption(InRange(offset, -255.0, 255.0), "FrameEffects::offset", offset,
                "-255 <= offset <= 255");
  for (const Occluder& occluder : occluders) occluder.Check();
}

void PoseSampling::Check() const {
  RequireOption(min_distance_m > 0.0, "PoseSampling::min_distance_m", min_distance_m,
                "min_distance_m > 0");
  RequireOption(max_distance_m >= min_distance_m && std::isfinite(max_distance_m),
                "PoseSampling::max_distance_m", max_distance_m, "min_distance_m <= max_distance_m");
  RequireOption(InRange(max_tilt_deg, 0.0, 80.0), "PoseSampling::max_tilt_deg", max_tilt_deg,
                "0 <= max_tilt_deg <= 80");
  RequireOption(max_offset_m >= 0.0 && std::isfinite(max_offset_m), "PoseSampling::max_offset_m",
                max_offset_m, "max_offset_m >= 0");
  RequireOption(min_visible_length_px >= 0.0 && std::isfinite(min_visible_length_px),
                "PoseSampling::min_visible_length_px", min_visible_length_px,
                "min_visible_length_px >= 0");
}

// -------------------------------------------------------------------------------------------
// Renderer.

SceneRenderer::SceneRenderer(LineTarget target, RenderOptions options)
    : target_(std::move(target)), options_(std::move(options)) {
  target_.Check();
  options_.Check();
  if (!options_.background_image.empty()) {
    // Checked first: OpenCV logs a warning when asked to read a missing file.
    const bool exists = std::ifstream(options_.background_image).good();
    const cv::Mat grey =
        exists ? cv::imread(options_.background_image, cv::IMREAD_GRAYSCALE) : cv::Mat();
    RequireOption(!grey.empty(), "RenderOptions::background_image",
                  "'" + options_.background_image + "'", "a readable image file");
    background_.resize(static_cast<unsigned>(grey.rows), static_cast<unsigned>(grey.cols));
    for (int r = 0; r < grey.rows; ++r) {
      std::copy_n(grey.ptr<unsigned char>(r), grey.cols, background_[r]);
    }
  }
  const std::size_t n = static_cast<std::size_t>(options_.width) * options_.height;
  ray_x_.resize(n);
  ray_y_.resize(n);
  for (int v = 0; v < options_.height; ++v) {
    for (int u = 0; u < options_.width; ++u) {
      double x = 0.0, y = 0.0;
      vpPixelMeterConversion::convertPoint(options_.camera, u, v, x, y);
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
  const BackgroundShade background(background_, options_.background_grey);
  const double board = target_.board_grey, line = target_.line_grey;

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
      const double around = c.board < 1.0 ? background.At(s.X, s.Y) : 0.0;
      row[u] =
          static_cast<float>(around * (1.0 - c.board) + board * (c.board - c.dark) + line * c.dark);
    }
  }
  PaintOccluders(effects.occluders, &radiance);
  ApplyIllumination(options_.illumination_gradient, options_.gradient_angle_rad, &radiance);
  ApplyGainOffset(effects.gain, effects.offset, &radiance);
  if (options_.blur_sigma_px > 0.0) {
    cv::GaussianBlur(radiance, radiance, cv::Size(), options_.blur_sigma_px, options_.blur_sigma_px,
                     cv::BORDER_REFLECT);
  }
  AddNoise(options_.noise_sigma, noise_seed, &radiance);

  RenderedFrame frame;
  frame.image.resize(static_cast<unsigned>(options_.height), static_cast<unsigned>(options_.width));
  cv::Mat out(options_.height, options_.width, CV_8U, frame.image.bitmap);
  radiance.convertTo(out, CV_8U);  // rounds and saturates to [0, 255]
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
    truth.push_back(
        LineTruth(target_.lines[i], static_cast<int>(i), cMo, options_, effects.occluders));
  }
  return truth;
}

// -------------------------------------------------------------------------------------------
// Lens helpers and pose sampling.

Point2d DistortedPixel(const vpCameraParameters& camera, double x, double y) {
  const double k = Kdu(camera);
  const double rho = std::hypot(x, y);
  double scale = 1.0;  // distorted over ideal normalised radius
  if (k != 0.0 && rho > 0.0) {
    const double r = DistortedRadius(k, rho);
    if (std::isnan(r)) return Point2d{kNaN, kNaN};
    scale = r / rho;
  }
  return Point2d{camera.get_u0() + camera.get_px() * x * scale,
                 camera.get_v0() + camera.get_py() * y * scale};
}

double FitKud(const vpCameraParameters& camera, int width, int height) {
  if (Kdu(camera) == 0.0) return 0.0;
  // Minimise sum over a grid of distorted pixels of |u0 + px x (1 + kud r^2) - u|^2 (and v),
  // (x, y) the ideal point of (u, v): linear in kud.
  constexpr int kSteps = 40;
  double saa = 0.0, sab = 0.0;
  for (int j = 0; j <= kSteps; ++j) {
    for (int i = 0; i <= kSteps; ++i) {
      const double u = (width - 1.0) * i / kSteps, v = (height - 1.0) * j / kSteps;
      double x = 0.0, y = 0.0;
      vpPixelMeterConversion::convertPoint(camera, u, v, x, y);
      const double r2 = x * x + y * y;
      const double au = camera.get_px() * x * r2, av = camera.get_py() * y * r2;
      const double bu = u - camera.get_u0() - camera.get_px() * x;
      const double bv = v - camera.get_v0() - camera.get_py() * y;
      saa += au * au + av * av;
      sab += au * bu + av * bv;
    }
  }
  return saa > 0.0 ? sab / saa : 0.0;
}

vpCameraParameters CameraWithKdu(double px, double py, double u0, double v0, double kdu, int width,
                                 int height) {
  vpCameraParameters camera;
  camera.initPersProjWithDistortion(px, py, u0, v0, 0.0, kdu);
  camera.initPersProjWithDistortion(px, py, u0, v0, FitKud(camera, width, height), kdu);
  return camera;
}

vpHomogeneousMatrix SamplePose(const SceneRenderer& renderer, const PoseSampling& sampling,
                               std::uint64_t* state) {
  sampling.Check();
  std::mt19937_64 gen(*state);
  for (int attempt = 0; attempt < 1000; ++attempt) {
    const vpHomogeneousMatrix cMo = DrawPose(sampling, gen);
    if (sampling.min_visible_length_px <= 0.0 ||
        LongEnough(renderer.Truth(cMo), sampling.min_visible_length_px)) {
      *state = gen();
      return cMo;
    }
  }
  std::ostringstream message;
  message << "SamplePose: none of 1000 poses shows every line of target '" << renderer.target().name
          << "' over min_visible_length_px = " << sampling.min_visible_length_px << " px";
  throw std::runtime_error(message.str());
}

}  // namespace oal
