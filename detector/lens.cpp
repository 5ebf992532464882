#include "detector/lens.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "base/check.h"

namespace oal {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace

double DistortedOverIdeal(double kdu, double rho2) {
  // rho = r (1 + kdu r^2) reads e s^3 + s = 1 in the ratio s = r / rho, with e = kdu rho^2:
  // solved by Newton, no square root and no division by rho. For kdu < 0 rho turns at
  // r^2 = -1 / (3 kdu), where rho^2 = -4 / (27 kdu); beyond, no s exists.
  if (kdu < 0.0 && rho2 > -4.0 / (27.0 * kdu)) return kNaN;
  const double e = kdu * rho2;
  auto newton_step = [e](double s) { return (e * s * s * s + s - 1.0) / (3.0 * e * s * s + 1.0); };
  if (std::fabs(e) < 0.1) {
    // The series s = 1 - e + 3 e^2 - 12 e^3 + 55 e^4 - ... is within 1 % of s here; each
    // Newton step squares the relative error times under 3 |e|: three leave under 1e-20 of
    // it, a fixed count with no test in the loop (the pose's projections are hot).
    double s = 1.0 + e * (-1.0 + e * (3.0 + e * (-12.0 + 55.0 * e)));
    s -= newton_step(s);
    s -= newton_step(s);
    s -= newton_step(s);
    return s;
  }
  // Newton from 1 / (1 + e) converges quadratically: a step under 1e-15 leaves none.
  double s = 1.0 / (1.0 + e);
  for (int i = 0; i < 200; ++i) {
    const double step = newton_step(s);
    s -= step;
    if (std::fabs(step) <= 1e-15) break;
  }
  return s;
}

Distortion Distortion::FromArray(const std::array<double, 8>& c) {
  return Distortion{c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]};
}

bool Distortion::IsZero() const {
  for (double c : ToArray()) {
    if (c != 0.0) return false;
  }
  return true;
}

Lens::Lens() : Lens(vpCameraParameters()) {}

Lens::Lens(const vpCameraParameters& camera)
    : px_(camera.get_px()), py_(camera.get_py()), u0_(camera.get_u0()), v0_(camera.get_v0()) {
  if (camera.get_projModel() == vpCameraParameters::perspectiveProjWithDistortion &&
      (camera.get_kdu() != 0.0 || camera.get_kud() != 0.0)) {
    model_ = Model::kViSP;
    kud_ = camera.get_kud();
    kdu_ = camera.get_kdu();
  }
}

Lens Lens::Pinhole(double px, double py, double u0, double v0) {
  return Lens(vpCameraParameters(px, py, u0, v0));
}

Lens Lens::WithKudKdu(double px, double py, double u0, double v0, double kud, double kdu) {
  Lens lens = Pinhole(px, py, u0, v0);
  if (kud != 0.0 || kdu != 0.0) {
    lens.model_ = Model::kViSP;
    lens.kud_ = kud;
    lens.kdu_ = kdu;
  }
  return lens;
}

Lens Lens::WithKdu(double px, double py, double u0, double v0, double kdu, int width, int height) {
  const Lens without_kud = WithKudKdu(px, py, u0, v0, 0.0, kdu);
  return WithKudKdu(px, py, u0, v0, FitKud(without_kud, width, height), kdu);
}

Lens Lens::WithDistortion(double px, double py, double u0, double v0,
                          const Distortion& distortion) {
  Lens lens = Pinhole(px, py, u0, v0);
  if (!distortion.IsZero()) {
    lens.model_ = Model::kOpenCV;
    lens.distortion_ = distortion;
    lens.max_ideal_r2_ = FoldRadius2(distortion);
  }
  return lens;
}

namespace {

// OpenCV's radial factor and its derivative in r^2.
struct Radial {
  double factor, slope;
};

[[gnu::always_inline]] inline Radial RadialOf(const Distortion& d, double r2) {
  if (d.k4 == 0.0 && d.k5 == 0.0 && d.k6 == 0.0) {  // plumb_bob: no division
    return Radial{1.0 + r2 * (d.k1 + r2 * (d.k2 + r2 * d.k3)),
                  d.k1 + r2 * (2.0 * d.k2 + 3.0 * r2 * d.k3)};
  }
  const double a = 1.0 + r2 * (d.k1 + r2 * (d.k2 + r2 * d.k3));
  const double b = 1.0 + r2 * (d.k4 + r2 * (d.k5 + r2 * d.k6));
  const double da = d.k1 + r2 * (2.0 * d.k2 + 3.0 * r2 * d.k3);
  const double db = d.k4 + r2 * (2.0 * d.k5 + 3.0 * r2 * d.k6);
  return Radial{a / b, (da * b - a * db) / (b * b)};
}

// d(r factor(r^2)) / dr: the radial map's slope, positive while it has not folded over.
double RadialMapSlope(const Distortion& d, double r2) {
  const Radial radial = RadialOf(d, r2);
  return radial.factor + 2.0 * r2 * radial.slope;
}

// OpenCV's forward map at the ideal point (x, y): the distorted point and its Jacobian.
struct Forward {
  double xd, yd, jxx, jxy, jyy;  // d xd / dy = d yd / dx = jxy
};

[[gnu::always_inline]] inline Forward ForwardOf(const Distortion& d, double x, double y) {
  const double r2 = x * x + y * y;
  const Radial radial = RadialOf(d, r2);
  Forward f;
  f.xd = x * radial.factor + 2.0 * d.p1 * x * y + d.p2 * (r2 + 2.0 * x * x);
  f.yd = y * radial.factor + d.p1 * (r2 + 2.0 * y * y) + 2.0 * d.p2 * x * y;
  f.jxx = radial.factor + 2.0 * x * x * radial.slope + 2.0 * d.p1 * y + 6.0 * d.p2 * x;
  f.jyy = radial.factor + 2.0 * y * y * radial.slope + 6.0 * d.p1 * y + 2.0 * d.p2 * x;
  f.jxy = 2.0 * x * y * radial.slope + 2.0 * d.p1 * x + 2.0 * d.p2 * y;
  return f;
}

// Calls f(u, v) on a 41 x 41 grid of pixels over a width x height image, its corners included:
// where a lens is fitted to another over the image, and compared with it.
template <typename F>
void ForEachGridPixel(int width, int height, F&& f) {
  constexpr int kSteps = 40;
  for (int j = 0; j <= kSteps; ++j) {
    for (int i = 0; i <= kSteps; ++i) f((width - 1.0) * i / kSteps, (height - 1.0) * j / kSteps);
  }
}

}  // namespace

double Lens::FoldRadius2(const Distortion& d) {
  // The first ideal radius where the radial map turns back, searched out to r = 20 (87
  // degrees off axis) in steps of 1/500; beyond, no lens users have is modelled.
  constexpr double kStep = 0.002, kFar = 20.0;
  for (double r = kStep; r <= kFar; r += kStep) {
    if (!(RadialMapSlope(d, r * r) > 0.0)) return (r - kStep) * (r - kStep);
  }
  return std::numeric_limits<double>::infinity();
}

Point2d Lens::Normalised(double u, double v) const {
  const double xd = (u - u0_) / px_, yd = (v - v0_) / py_;
  switch (model_) {
    case Model::kPinhole:
      return Point2d{xd, yd};
    case Model::kViSP: {
      const double factor = 1.0 + kdu_ * (xd * xd + yd * yd);
      return Point2d{xd * factor, yd * factor};
    }
    case Model::kOpenCV:
      break;
  }
  // From one step of the fixed-point iteration: the distorted point divided by its radial
  // factor.
  const double rd2 = xd * xd + yd * yd;
  const double start = rd2 < max_ideal_r2_ ? RadialOf(distortion_, rd2).factor : 1.0;
  const double inverse_start = start > 0.2 ? 1.0 / start : 1.0;
  Point2d guess{xd * inverse_start, yd * inverse_start};
  if (guess.u * guess.u + guess.v * guess.v > max_ideal_r2_) guess = Point2d{xd, yd};
  return SolveFrom(xd, yd, guess);
}

Point2d Lens::SolveFrom(double xd, double yd, const Point2d& guess) const {
  // Newton's method on the forward map; the Jacobian's determinant stays positive inside the
  // fold radius, and a step that leaves it is halved. It stops once the forward map lands
  // within 1e-13 of the distorted point (a millionth of a pixel for any focal length under
  // 10^7 px), or the step that got there was under 1e-5: Newton's error after a step is of
  // the order of the step squared, 1e-10 (under 1e-7 px for the lenses of config/lenses; the
  // round trip is tested to 1e-6 px). Usually two steps.
  double x = guess.u, y = guess.v;
  for (int iteration = 0; iteration < 50; ++iteration) {
    const Forward f = ForwardOf(distortion_, x, y);
    const double fx = f.xd - xd, fy = f.yd - yd;
    if (std::fabs(fx) + std::fabs(fy) <= 1e-13) return Point2d{x, y};
    const double det = f.jxx * f.jyy - f.jxy * f.jxy;
    if (!(det > 0.0)) return Point2d{kNaN, kNaN};
    const double inverse_det = 1.0 / det;
    double sx = (f.jyy * fx - f.jxy * fy) * inverse_det;
    double sy = (f.jxx * fy - f.jxy * fx) * inverse_det;
    for (int halving = 0; halving < 60 && (x - sx) * (x - sx) + (y - sy) * (y - sy) > max_ideal_r2_;
         ++halving) {
      sx *= 0.5;
      sy *= 0.5;
    }
    x -= sx;
    y -= sy;
    if (std::fabs(sx) + std::fabs(sy) <= 1e-5) return Point2d{x, y};
  }
  return Point2d{kNaN, kNaN};
}

Point2d Lens::Pixel(double x, double y) const {
  switch (model_) {
    case Model::kPinhole:
      return Point2d{u0_ + px_ * x, v0_ + py_ * y};
    case Model::kViSP: {
      const double scale = DistortedOverIdeal(kdu_, x * x + y * y);
      if (std::isnan(scale)) return Point2d{kNaN, kNaN};
      return Point2d{u0_ + px_ * x * scale, v0_ + py_ * y * scale};
    }
    case Model::kOpenCV:
      break;
  }
  if (!(x * x + y * y <= max_ideal_r2_)) return Point2d{kNaN, kNaN};
  const Forward f = ForwardOf(distortion_, x, y);
  return Point2d{u0_ + px_ * f.xd, v0_ + py_ * f.yd};
}

std::array<double, 4> Lens::NormalisedDerivative(double u, double v, const Point2d& ideal) const {
  const double inv_px = 1.0 / px_, inv_py = 1.0 / py_;
  switch (model_) {
    case Model::kPinhole:
      return {inv_px, 0.0, 0.0, inv_py};
    case Model::kViSP: {
      // x = du (1 + k r^2), du = (u - u0) / px, likewise y.
      const double du = (u - u0_) * inv_px, dv = (v - v0_) * inv_py;
      const double f = 1.0 + kdu_ * (du * du + dv * dv), cross = 2.0 * kdu_ * du * dv;
      return {(f + 2.0 * kdu_ * du * du) * inv_px, cross * inv_py, cross * inv_px,
              (f + 2.0 * kdu_ * dv * dv) * inv_py};
    }
    case Model::kOpenCV:
      break;
  }
  // The inverse of the forward map's Jacobian at the ideal point.
  const Forward f = ForwardOf(distortion_, ideal.u, ideal.v);
  const double inv_det = 1.0 / (f.jxx * f.jyy - f.jxy * f.jxy);
  return {f.jyy * inv_det * inv_px, -f.jxy * inv_det * inv_py, -f.jxy * inv_det * inv_px,
          f.jxx * inv_det * inv_py};
}

vpCameraParameters Lens::PinholeCamera() const {
  return vpCameraParameters(px_, py_, u0_, v0_);
}

vpCameraParameters Lens::ViSPCamera(int width, int height) const {
  vpCameraParameters camera = PinholeCamera();
  if (model_ == Model::kViSP) {
    camera.initPersProjWithDistortion(px_, py_, u0_, v0_, kud_, kdu_);
  } else if (model_ == Model::kOpenCV) {
    // Least squares over a grid of the image's pixels of the ideal pixel error of
    // x = xd (1 + kdu rd^2): linear in kdu.
    double saa = 0.0, sab = 0.0;
    ForEachGridPixel(width, height, [&](double u, double v) {
      const Point2d ideal = Normalised(u, v);
      if (!std::isfinite(ideal.u)) return;
      const double xd = (u - u0_) / px_, yd = (v - v0_) / py_, rd2 = xd * xd + yd * yd;
      const double au = px_ * xd * rd2, av = py_ * yd * rd2;
      saa += au * au + av * av;
      sab += au * px_ * (ideal.u - xd) + av * py_ * (ideal.v - yd);
    });
    const double kdu = saa > 0.0 ? sab / saa : 0.0;
    const Lens one_term = WithKdu(px_, py_, u0_, v0_, kdu, width, height);
    camera.initPersProjWithDistortion(px_, py_, u0_, v0_, one_term.kud(), one_term.kdu());
  }
  return camera;
}

Lens Lens::OpenCvCamera(int width, int height) const {
  if (model_ != Model::kViSP) return *this;
  // Minimise over a grid of distorted pixels (u, v) the distance from (u, v) to
  // u0 + px x (1 + k1 r^2 + k2 r^4 + k3 r^6) (and v), (x, y) the ideal point of (u, v): linear
  // in (k1, k2, k3), solved by its 3 x 3 normal equations.
  double a[3][3] = {}, b[3] = {};
  ForEachGridPixel(width, height, [&](double u, double v) {
    const Point2d ideal = Normalised(u, v);
    if (!std::isfinite(ideal.u)) return;
    const double r2 = ideal.u * ideal.u + ideal.v * ideal.v;
    const double powers[3] = {r2, r2 * r2, r2 * r2 * r2};
    const double bu = u - u0_ - px_ * ideal.u, bv = v - v0_ - py_ * ideal.v;
    for (int r = 0; r < 3; ++r) {
      const double ur = px_ * ideal.u * powers[r], vr = py_ * ideal.v * powers[r];
      b[r] += ur * bu + vr * bv;
      for (int c = 0; c < 3; ++c) {
        a[r][c] += ur * px_ * ideal.u * powers[c] + vr * py_ * ideal.v * powers[c];
      }
    }
  });
  const auto det3 = [](const double m[3][3]) {
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
           m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  };
  const double det = det3(a);
  if (!(std::fabs(det) > 0.0)) return Pinhole(px_, py_, u0_, v0_);
  double k[3];
  for (int c = 0; c < 3; ++c) {  // Cramer's rule
    double m[3][3];
    for (int r = 0; r < 3; ++r) {
      for (int cc = 0; cc < 3; ++cc) m[r][cc] = cc == c ? b[r] : a[r][cc];
    }
    k[c] = det3(m) / det;
  }
  Distortion fitted;
  fitted.k1 = k[0];
  fitted.k2 = k[1];
  fitted.k3 = k[2];
  return WithDistortion(px_, py_, u0_, v0_, fitted);
}

bool Lens::operator==(const Lens& other) const {
  return model_ == other.model_ && px_ == other.px_ && py_ == other.py_ && u0_ == other.u0_ &&
         v0_ == other.v0_ && kud_ == other.kud_ && kdu_ == other.kdu_ &&
         distortion_ == other.distortion_;
}

std::string LensModelName(const Lens& lens) {
  switch (lens.model()) {
    case Lens::Model::kPinhole:
      return "perspectiveProjWithoutDistortion";
    case Lens::Model::kViSP:
      return "perspectiveProjWithDistortion";
    case Lens::Model::kOpenCV:
      break;
  }
  return lens.distortion().IsRational() ? "rational_polynomial" : "plumb_bob";
}

PointUndistorter::PointUndistorter(const Lens& lens)
    : lens_(lens),
      inv_px2_(1.0 / (lens.px() * lens.px())),
      inv_py2_(1.0 / (lens.py() * lens.py())) {}

double FitKud(const Lens& lens, int width, int height) {
  if (lens.kdu() == 0.0) return 0.0;
  // Minimise sum over a grid of distorted pixels of |u0 + px x (1 + kud r^2) - u|^2 (and v),
  // (x, y) the ideal point of (u, v): linear in kud.
  double saa = 0.0, sab = 0.0;
  ForEachGridPixel(width, height, [&](double u, double v) {
    const Point2d ideal = lens.Normalised(u, v);
    const double x = ideal.u, y = ideal.v, r2 = x * x + y * y;
    const double au = lens.px() * x * r2, av = lens.py() * y * r2;
    const double bu = u - lens.u0() - lens.px() * x;
    const double bv = v - lens.v0() - lens.py() * y;
    saa += au * au + av * av;
    sab += au * bu + av * bv;
  });
  return saa > 0.0 ? sab / saa : 0.0;
}

double WorstIdealPixelDifference(const Lens& a, const Lens& b, int width, int height,
                                 double max_radius_px) {
  double worst = 0.0;
  ForEachGridPixel(width, height, [&](double u, double v) {
    if (std::hypot(u - a.u0(), v - a.v0()) > max_radius_px) return;
    const Point2d p = a.Normalised(u, v), q = b.Normalised(u, v);
    const double d = std::hypot(a.px() * p.u - b.px() * q.u + a.u0() - b.u0(),
                                a.py() * p.v - b.py() * q.v + a.v0() - b.v0());
    worst = std::isfinite(d) ? std::max(worst, d) : std::numeric_limits<double>::infinity();
  });
  return worst;
}

double CornerRadius2(const Lens& lens, int width, int height) {
  const double du = std::max(std::fabs(lens.u0()), std::fabs(width - 1 - lens.u0()));
  const double dv = std::max(std::fabs(lens.v0()), std::fabs(height - 1 - lens.v0()));
  return du * du / (lens.px() * lens.px()) + dv * dv / (lens.py() * lens.py());
}

void CheckPerspectiveCamera(const Lens& lens, const std::string& field) {
  // A lens that passes builds none of the field names (the pose checks its camera every frame).
  const auto coefficients = lens.distortion().ToArray();
  bool finite = std::isfinite(lens.u0()) && std::isfinite(lens.v0()) && std::isfinite(lens.kdu()) &&
                std::isfinite(lens.kud());
  for (const double c : coefficients) finite = finite && std::isfinite(c);
  if (finite && lens.px() > 0.0 && std::isfinite(lens.px()) && lens.py() > 0.0 &&
      std::isfinite(lens.py())) {
    return;
  }
  RequireOption(lens.px() > 0.0 && std::isfinite(lens.px()), field + ".px", lens.px(), "px > 0");
  RequireOption(lens.py() > 0.0 && std::isfinite(lens.py()), field + ".py", lens.py(), "py > 0");
  RequireOption(std::isfinite(lens.u0()), field + ".u0", lens.u0(), "u0 is finite");
  RequireOption(std::isfinite(lens.v0()), field + ".v0", lens.v0(), "v0 is finite");
  RequireOption(std::isfinite(lens.kdu()), field + ".kdu", lens.kdu(), "kdu is finite");
  RequireOption(std::isfinite(lens.kud()), field + ".kud", lens.kud(), "kud is finite");
  for (std::size_t i = 0; i < coefficients.size(); ++i) {
    RequireOption(std::isfinite(coefficients[i]), field + "." + Distortion::kNames[i],
                  coefficients[i], std::string(Distortion::kNames[i]) + " is finite");
  }
}

void CheckInvertibleOver(const Lens& lens, int width, int height, const std::string& field) {
  if (lens.model() == Lens::Model::kViSP) {
    // The pixel -> ray map must not fold over inside the image: 1 + 3 kdu r^2 > 0 at the
    // farthest corner (the radial derivative of r (1 + kdu r^2)).
    const double r2 = CornerRadius2(lens, width, height);
    RequireOption(1.0 + 3.0 * lens.kdu() * r2 > 0.0, field + ".kdu", lens.kdu(),
                  "1 + 3 kdu r^2 > 0 at the image corners (the lens model is invertible)");
  } else if (lens.model() == Lens::Model::kOpenCV) {
    // Every pixel of the image's rim has an ideal point inside the fold radius (the radial
    // map is monotonic there, so the inside has too).
    bool invertible = true;
    const int steps = 64;
    for (int i = 0; i <= steps && invertible; ++i) {
      const double u = (width - 1.0) * i / steps, v = (height - 1.0) * i / steps;
      for (const Point2d& p :
           {Point2d{u, 0.0}, Point2d{u, height - 1.0}, Point2d{0.0, v}, Point2d{width - 1.0, v}}) {
        invertible = invertible && std::isfinite(lens.Normalised(p.u, p.v).u);
      }
    }
    RequireOption(invertible, field + ".k1", lens.distortion().k1,
                  "the distortion model maps every pixel of the image to a ray (it folds over "
                  "inside the image)");
  }
}

}  // namespace oal
