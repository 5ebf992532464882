#include "detector/lens.h"

#include <visp3/core/vpPixelMeterConversion.h>

#include <cmath>
#include <limits>

#include "base/check.h"

namespace oal {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace

double Kdu(const vpCameraParameters& camera) {
  return camera.get_projModel() == vpCameraParameters::perspectiveProjWithDistortion
             ? camera.get_kdu()
             : 0.0;
}

// Undistort() is vpPixelMeterConversion::convertPoint (distorted pixel -> metre, with kdu)
// followed by x -> u0 + px * x, folded into one expression; tests/detector/lens_test.cpp
// checks it against ViSP's own conversion.
PointUndistorter::PointUndistorter(const vpCameraParameters& camera)
    : u0_(camera.get_u0()),
      v0_(camera.get_v0()),
      inv_px2_(1.0 / (camera.get_px() * camera.get_px())),
      inv_py2_(1.0 / (camera.get_py() * camera.get_py())),
      kdu_(Kdu(camera)) {}

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

Point2d DistortedPixel(const vpCameraParameters& camera, double x, double y) {
  const double k = Kdu(camera);
  const double scale = k != 0.0 ? DistortedOverIdeal(k, x * x + y * y) : 1.0;
  if (std::isnan(scale)) return Point2d{kNaN, kNaN};
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

void CheckPerspectiveCamera(const vpCameraParameters& camera, const std::string& field) {
  const auto model = camera.get_projModel();
  RequireOption(model == vpCameraParameters::perspectiveProjWithoutDistortion ||
                    model == vpCameraParameters::perspectiveProjWithDistortion,
                field + ".projModel", static_cast<int>(model),
                "perspective projection with or without (kdu) distortion");
  RequireOption(camera.get_px() > 0.0 && std::isfinite(camera.get_px()), field + ".px",
                camera.get_px(), "px > 0");
  RequireOption(camera.get_py() > 0.0 && std::isfinite(camera.get_py()), field + ".py",
                camera.get_py(), "py > 0");
  RequireOption(std::isfinite(camera.get_u0()), field + ".u0", camera.get_u0(), "u0 is finite");
  RequireOption(std::isfinite(camera.get_v0()), field + ".v0", camera.get_v0(), "v0 is finite");
}

}  // namespace oal
