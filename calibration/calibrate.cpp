#include "calibration/calibrate.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <sstream>
#include <stdexcept>

#include "base/check.h"
#include "base/format.h"

namespace oal {
namespace {

constexpr double kDegPerRad = 180.0 / 3.14159265358979323846;

// How far a relative standard deviation (or a pixel one for the principal point) may go
// before the result says which parameter the views leave loose.
constexpr double kLooseFocalFraction = 0.003;
constexpr double kLoosePrincipalPx = 1.5;
constexpr double kLooseK1 = 0.01;

// The view's plane tilt from its rotation vector: the angle between the plane's normal (its z
// axis) and the optical axis.
double TiltDeg(const cv::Mat& rvec) {
  cv::Mat rotation;
  cv::Rodrigues(rvec, rotation);
  const double cos_tilt = std::fabs(rotation.at<double>(2, 2));
  return std::acos(std::min(1.0, cos_tilt)) * kDegPerRad;
}

}  // namespace

void CalibrationOptions::Check() const {
  RequireOption(width > 0 && width <= 65536, "CalibrationOptions::width", width, "0 < width");
  RequireOption(height > 0 && height <= 65536, "CalibrationOptions::height", height, "0 < height");
  RequireOption(min_views >= 3 && min_views <= 1000, "CalibrationOptions::min_views", min_views,
                "3 <= min_views <= 1000");
  RequireOption(min_points_per_view >= 6 && min_points_per_view <= 100000,
                "CalibrationOptions::min_points_per_view", min_points_per_view,
                "6 <= min_points_per_view <= 100000");
  RequireOption(min_tilt_deg >= 0.0 && min_tilt_deg <= 80.0, "CalibrationOptions::min_tilt_deg",
                min_tilt_deg, "0 <= min_tilt_deg <= 80");
  RequireOption(min_tilted_views >= 0 && min_tilted_views <= 1000,
                "CalibrationOptions::min_tilted_views", min_tilted_views,
                "0 <= min_tilted_views <= 1000");
}

RadialFit FitViSPDistortion(const RadialDistortion& lens, double px, double py, double u0,
                            double v0, int width, int height, double max_radius) {
  // On a 32 x 32 grid of distorted pixels over the image: the ideal point x_u of each
  // distorted one x_d (inverting x_d = x_u f(r_u^2) by fixed-point iteration), then each
  // coefficient by linear least squares: kdu from x_u = x_d (1 + kdu r_d^2), kud from
  // x_d = x_u (1 + kud r_u^2).
  double kdu_num = 0.0, kdu_den = 0.0, kud_num = 0.0, kud_den = 0.0;
  constexpr int kGrid = 32;
  for (int j = 0; j <= kGrid; ++j) {
    for (int i = 0; i <= kGrid; ++i) {
      const double xd = ((width - 1.0) * i / kGrid - u0) / px;
      const double yd = ((height - 1.0) * j / kGrid - v0) / py;
      if (xd * xd + yd * yd > max_radius * max_radius) continue;
      double xu = xd, yu = yd;
      for (int iteration = 0; iteration < 100; ++iteration) {
        const double r2 = xu * xu + yu * yu;
        const double factor = 1.0 + r2 * (lens.k1 + r2 * (lens.k2 + r2 * lens.k3));
        if (!(std::fabs(factor) > 1e-6)) break;
        xu = xd / factor;
        yu = yd / factor;
      }
      const double rd2 = xd * xd + yd * yd, ru2 = xu * xu + yu * yu;
      kdu_num += xd * rd2 * (xu - xd) + yd * rd2 * (yu - yd);
      kdu_den += (xd * rd2) * (xd * rd2) + (yd * rd2) * (yd * rd2);
      kud_num += xu * ru2 * (xd - xu) + yu * ru2 * (yd - yu);
      kud_den += (xu * ru2) * (xu * ru2) + (yu * ru2) * (yu * ru2);
    }
  }
  return RadialFit{kud_den > 0.0 ? kud_num / kud_den : 0.0,
                   kdu_den > 0.0 ? kdu_num / kdu_den : 0.0};
}

CalibrationResult Calibrate(const std::vector<CalibrationView>& views,
                            const CalibrationOptions& options) {
  options.Check();
  CalibrationResult result;
  std::vector<std::vector<cv::Point3f>> object_points;
  std::vector<std::vector<cv::Point2f>> image_points;
  std::vector<std::size_t> used;  // index in `views` of each view handed to the solver
  for (std::size_t k = 0; k < views.size(); ++k) {
    const CalibrationView& view = views[k];
    CalibrationViewReport& report = result.views.emplace_back();
    report.name = view.name;
    report.points = static_cast<int>(view.points.size());
    if (report.points < options.min_points_per_view) {
      report.rejected = std::to_string(report.points) + " target points (min_points_per_view = " +
                        std::to_string(options.min_points_per_view) + ")";
      continue;
    }
    std::vector<cv::Point3f>& object = object_points.emplace_back();
    std::vector<cv::Point2f>& image = image_points.emplace_back();
    for (const CalibrationPoint& point : view.points) {
      object.emplace_back(static_cast<float>(point.x), static_cast<float>(point.y), 0.0f);
      image.emplace_back(static_cast<float>(point.u), static_cast<float>(point.v));
    }
    used.push_back(k);
  }
  if (static_cast<int>(used.size()) < options.min_views) {
    std::ostringstream message;
    message << used.size() << " usable view" << (used.size() == 1 ? "" : "s") << " of "
            << views.size() << ", at least " << options.min_views << " needed";
    for (const CalibrationViewReport& report : result.views) {
      if (!report.rejected.empty()) message << "\n  " << report.name << ": " << report.rejected;
    }
    throw std::runtime_error(message.str());
  }

  // Two radial terms: enough to follow a lens that ViSP's one-term model in either direction
  // describes (the inverse of one term is a series), so that px, py, u0, v0 are not bent to
  // absorb what one term misses; a third follows the noise where the views have few points.
  int flags = cv::CALIB_ZERO_TANGENT_DIST | cv::CALIB_FIX_K3;
  if (!options.estimate_distortion) flags |= cv::CALIB_FIX_K1 | cv::CALIB_FIX_K2;
  cv::Mat camera_matrix, distortion = cv::Mat::zeros(5, 1, CV_64F), sd_intrinsics, sd_extrinsics,
                         view_errors;
  std::vector<cv::Mat> rvecs, tvecs;
  const cv::TermCriteria stop(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-12);
  result.rms_px = cv::calibrateCamera(
      object_points, image_points, cv::Size(options.width, options.height), camera_matrix,
      distortion, rvecs, tvecs, sd_intrinsics, sd_extrinsics, view_errors, flags, stop);

  int tilted = 0;
  double largest_tilt = 0.0;
  for (std::size_t i = 0; i < used.size(); ++i) {
    CalibrationViewReport& report = result.views[used[i]];
    report.used = true;
    report.rms_px = view_errors.at<double>(static_cast<int>(i));
    report.tilt_deg = TiltDeg(rvecs[i]);
    largest_tilt = std::max(largest_tilt, report.tilt_deg);
    tilted += report.tilt_deg >= options.min_tilt_deg;
  }
  if (tilted < options.min_tilted_views) {
    throw std::runtime_error(
        "the views are nearly all facing the camera (" + std::to_string(tilted) + " tilted by " +
        Fixed(options.min_tilt_deg, 0) + " deg or more, the most " + Fixed(largest_tilt, 1) +
        " deg; at least " + std::to_string(options.min_tilted_views) +
        " needed): the focal length cannot be told from the distance. Tilt the target by "
        "20-45 deg, in different directions, in several views");
  }

  const double px = camera_matrix.at<double>(0, 0), py = camera_matrix.at<double>(1, 1);
  const double u0 = camera_matrix.at<double>(0, 2), v0 = camera_matrix.at<double>(1, 2);
  result.lens = RadialDistortion{distortion.at<double>(0), distortion.at<double>(1),
                                 distortion.at<double>(4)};
  if (options.estimate_distortion) {
    // Over the part of the image the views cover: beyond it the lens is extrapolated.
    double max_radius = 0.0;
    for (const std::vector<cv::Point2f>& view : image_points) {
      for (const cv::Point2f& p : view) {
        max_radius = std::max(max_radius, std::hypot((p.x - u0) / px, (p.y - v0) / py));
      }
    }
    const RadialFit visp =
        FitViSPDistortion(result.lens, px, py, u0, v0, options.width, options.height, max_radius);
    result.camera.initPersProjWithDistortion(px, py, u0, v0, visp.kud, visp.kdu);
  } else {
    result.camera.initPersProjWithoutDistortion(px, py, u0, v0);
  }
  result.px_sd = sd_intrinsics.at<double>(0);
  result.py_sd = sd_intrinsics.at<double>(1);
  result.u0_sd = sd_intrinsics.at<double>(2);
  result.v0_sd = sd_intrinsics.at<double>(3);
  result.k1_sd = options.estimate_distortion ? sd_intrinsics.at<double>(4) : 0.0;

  if (result.px_sd > kLooseFocalFraction * px || result.py_sd > kLooseFocalFraction * py) {
    result.advice.push_back("px, py are known to +-" + Fixed(100.0 * result.px_sd / px, 2) +
                            " %: tilt the target more (30-45 deg), in different directions");
  }
  if (result.u0_sd > kLoosePrincipalPx || result.v0_sd > kLoosePrincipalPx) {
    result.advice.push_back("u0, v0 are known to +-" +
                            Fixed(std::max(result.u0_sd, result.v0_sd), 1) +
                            " px: add views tilted about both image axes");
  }
  if (result.k1_sd > kLooseK1) {
    result.advice.push_back("the distortion is known to +-" + Fixed(result.k1_sd, 3) +
                            ": add views with the target near the image's corners");
  }
  return result;
}

}  // namespace oal
