#include "calibration/calibrate.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "base/angles.h"
#include "base/check.h"
#include "base/format.h"
#include "base/statistics.h"
#include "calibration/plane_lines.h"

namespace oal {
namespace {

using plane_lines::OnPlane;
using plane_lines::PlaneLine;
using plane_lines::Snap;

// How far a relative standard deviation (or a pixel one for the principal point) may go
// before the result says which parameter the views leave loose.
constexpr double kLooseFocalFraction = 0.003;
constexpr double kLoosePrincipalPx = 1.5;
constexpr double kLooseK1 = 0.01;
// Views whose points reach less than this fraction of the way to the image's corners leave the
// lens there extrapolated.
constexpr double kCoveredFraction = 0.8;
// k3 is fitted only when the views reach this fraction of the way to the image's corners.
constexpr double kK3Reach = 0.6;

// The largest distorted normalised radius of the views' points.
double Reach(const std::vector<std::vector<cv::Point2f>>& image_points, const cv::Mat& k) {
  double reach2 = 0.0;
  for (const std::vector<cv::Point2f>& view : image_points) {
    for (const cv::Point2f& p : view) {
      reach2 = std::max(reach2, std::pow((p.x - k.at<double>(0, 2)) / k.at<double>(0, 0), 2) +
                                    std::pow((p.y - k.at<double>(1, 2)) / k.at<double>(1, 1), 2));
    }
  }
  return std::sqrt(reach2);
}

// Points on lines are paired with plane points again after each solve until none moves by
// more than this (metres), or this many solves.
constexpr double kPairingSettledM = 1e-6;
constexpr int kMaxPairingRounds = 40;
// A run crosses its stripe from edge to edge when its ends lie this far inside the stripe's
// printed ends (times its width) and it spans its width within this fraction (the runs of a
// blurred stripe are a few tenths of a pixel short).
constexpr double kRunEndMarginWidths = 0.5;
constexpr double kRunSpanTolerance = 0.3;
// calibrateCamera's share of each view's line points (see gather).
constexpr std::size_t kSolverLinePointsPerView = 256;
// Runs' middles are moved again after each solve (CentreRuns) until none moves by more than
// this, pixels.
constexpr double kCentringSettledPx = 1e-3;
// The polish on the lines' distances stops when a step lowers their sum of squares by less than
// this fraction, or after this many steps.
constexpr double kPolishSettled = 1e-10;
constexpr int kPolishIterations = 50;
// A line point farther from its line than this many robust standard deviations of them all is
// left out, but not nearer than the floor (pixels).
constexpr double kOutlierSigmas = 4.0;
constexpr double kOutlierFloorPx = 0.3;
// A view whose points fit this many times worse than the median view's, and worse than the
// floor (pixels), is left out.
constexpr double kViewOutlierRatio = 2.0;
constexpr double kViewOutlierFloorPx = 0.3;
// Rounds of solving, polishing and judging the points, at most, until none changes sides (a
// view left out as a whole always gets its round).
constexpr int kMaxJudgingRounds = 10;

// The view's plane tilt from its rotation vector: the angle between the plane's normal (its z
// axis) and the optical axis.
double TiltDeg(const cv::Mat& rvec) {
  cv::Mat rotation;
  cv::Rodrigues(rvec, rotation);
  const double cos_tilt = std::fabs(rotation.at<double>(2, 2));
  return std::acos(std::min(1.0, cos_tilt)) * kDegPerRad;
}

// Each seen point of a view's lines paired with a plane point of its line: where the
// homography (first pairing) or the solved camera and view pose (later ones) take it back to
// the plane, moved across onto the line. Pairing again after each solve converges to the
// points' fit across their lines: along a line, the pairing leaves no residual.
struct LinePairing {
  std::vector<cv::Point2d> seen;     // distorted pixels, a run's middle moved (CentreRuns)
  std::vector<cv::Point2d> middle;   // as given
  std::vector<cv::Point2d> run;      // the run across its stripe, (0, 0) when unknown
  std::vector<std::size_t> line_of;  // index in the view's lines
  std::vector<cv::Point2d> paired;   // plane, metres
  std::vector<char> outlier;         // left out of the solve, for now (MarkOutliers)
  std::vector<char> partial_run;     // a run not across its stripe, for now (CentreRuns)

  bool used(std::size_t k) const { return !outlier[k] && !partial_run[k]; }
  std::size_t kept() const {
    std::size_t count = 0;
    for (std::size_t k = 0; k < seen.size(); ++k) count += used(k);
    return count;
  }
};

LinePairing PairThroughHomography(const CalibrationView& view, const cv::Matx33d& plane_to_image) {
  LinePairing pairing;
  const cv::Matx33d image_to_plane = plane_to_image.inv();
  for (std::size_t l = 0; l < view.lines.size(); ++l) {
    const PlaneLine line = OnPlane(view.lines[l]);
    const CalibrationLine& seen_line = view.lines[l];
    for (std::size_t k = 0; k < seen_line.seen.size(); ++k) {
      const Point2d& p = seen_line.seen[k];
      const cv::Vec3d q = image_to_plane * cv::Vec3d(p.u, p.v, 1.0);
      pairing.seen.emplace_back(p.u, p.v);
      pairing.middle.emplace_back(p.u, p.v);
      const bool has_run = seen_line.width_m > 0.0 && k < seen_line.runs.size();
      pairing.run.push_back(has_run ? cv::Point2d(seen_line.runs[k].u, seen_line.runs[k].v)
                                    : cv::Point2d(0.0, 0.0));
      pairing.line_of.push_back(l);
      pairing.paired.push_back(Snap(line, cv::Point2d(q[0] / q[2], q[1] / q[2])));
      pairing.outlier.push_back(0);
      pairing.partial_run.push_back(0);
    }
  }
  return pairing;
}

// The camera a solve has reached, as a Lens.
Lens SolvedLens(const cv::Mat& camera_matrix, const cv::Mat& distortion) {
  std::array<double, 8> coefficients{};
  for (int i = 0; i < distortion.rows * distortion.cols && i < 8; ++i) {
    coefficients[static_cast<std::size_t>(i)] = distortion.at<double>(i);
  }
  return Lens::WithDistortion(camera_matrix.at<double>(0, 0), camera_matrix.at<double>(1, 1),
                              camera_matrix.at<double>(0, 2), camera_matrix.at<double>(1, 2),
                              Distortion::FromArray(coefficients));
}

// Where the solved camera and view pose take distorted pixels back to the view's plane: each
// pixel's ray meets it (NaN for a ray along it).
std::vector<cv::Point2d> OnViewPlane(const std::vector<cv::Point2d>& pixels,
                                     const cv::Mat& camera_matrix, const cv::Mat& distortion,
                                     const cv::Mat& rvec, const cv::Mat& tvec) {
  std::vector<cv::Point2d> plane;
  if (pixels.empty()) return plane;
  // Through the lens's own Newton solve: cv::undistortPoints' five fixed-point steps leave a
  // strong lens's outer points pixels off, and the pairing would settle where they put them.
  const Lens lens = SolvedLens(camera_matrix, distortion);
  cv::Matx33d rotation;
  cv::Rodrigues(rvec, rotation);
  const cv::Matx33d plane_from_camera = rotation.t();
  const cv::Vec3d centre = -(plane_from_camera * cv::Vec3d(tvec));
  for (const cv::Point2d& pixel : pixels) {
    const Point2d x = lens.Normalised(pixel.x, pixel.y);
    const cv::Vec3d ray = plane_from_camera * cv::Vec3d(x.u, x.v, 1.0);
    const double s = std::fabs(ray[2]) < 1e-12 ? std::nan("") : -centre[2] / ray[2];
    plane.emplace_back(centre[0] + s * ray[0], centre[1] + s * ray[1]);
  }
  return plane;
}

// Where along a run, t in [-1, 1] from one end to the other, the quadratic through the runs'
// ends and middle, `across` at t = -1, 0, 1, reaches `value` (Newton from the chord's answer).
double WhereAcross(const std::array<double, 3>& across, double value) {
  const double c0 = across[1], c1 = 0.5 * (across[2] - across[0]),
               c2 = 0.5 * (across[2] + across[0]) - across[1];
  double t = (value - c0) / c1;
  for (int iteration = 0; iteration < 3; ++iteration) {
    t -= (c0 + t * (c1 + t * c2) - value) / (c1 + 2.0 * t * c2);
  }
  return t;
}

// Moves each run's middle along its run to where the solved camera and view pose put the
// centre line of its stripe: the middle of a run between the images of the two edges is off
// the image of the centre line, by how perspective and the lens bend the stripe across
// (hundredths of a pixel, a tenth near the corners of a strong lens: enough to bias the focal
// length and the lens if left). Each run's span is taken back to the plane at its ends and
// middle; where it crosses the edges and the centre follows from the quadratic through them.
// Returns the largest change of a point's move, pixels (infinite when a run was left out or
// taken back).
double CentreRuns(const CalibrationView& view, const cv::Mat& camera_matrix,
                  const cv::Mat& distortion, const cv::Mat& rvec, const cv::Mat& tvec,
                  LinePairing* pairing) {
  std::vector<std::size_t> with_run;
  std::vector<cv::Point2d> samples;
  for (std::size_t k = 0; k < pairing->seen.size(); ++k) {
    if (pairing->run[k] == cv::Point2d(0.0, 0.0)) continue;
    with_run.push_back(k);
    for (const double t : {-0.5, 0.0, 0.5})
      samples.push_back(pairing->middle[k] + t * pairing->run[k]);
  }
  const std::vector<cv::Point2d> plane =
      OnViewPlane(samples, camera_matrix, distortion, rvec, tvec);
  double changed = 0.0;
  for (std::size_t i = 0; i < with_run.size(); ++i) {
    const std::size_t k = with_run[i];
    const CalibrationLine& seen_line = view.lines[pairing->line_of[k]];
    const PlaneLine line = OnPlane(seen_line);
    std::array<double, 3> across{};
    for (std::size_t j = 0; j < 3; ++j) {
      across[j] = (plane[3 * i + j] - line.point).cross(line.direction);
    }
    const double half = 0.5 * seen_line.width_m;
    // A run that does not cross its stripe from edge to edge (one through the stripe's end,
    // cut short by a mark, or run on into a shadow) has its middle off the centre line by
    // pixels; it is left out while the camera says so.
    const double length = std::hypot(seen_line.dx, seen_line.dy);
    const double margin = kRunEndMarginWidths * seen_line.width_m;
    bool across_stripe =
        std::fabs(std::fabs(across[2] - across[0]) / seen_line.width_m - 1.0) < kRunSpanTolerance;
    for (const std::size_t j : {std::size_t{0}, std::size_t{2}}) {
      const double along = (plane[3 * i + j] - line.point).dot(line.direction);
      across_stripe = across_stripe && along > margin && along < length - margin;
    }
    if (pairing->partial_run[k] != (across_stripe ? 0 : 1)) changed = HUGE_VAL;
    pairing->partial_run[k] = across_stripe ? 0 : 1;
    const double shift =
        WhereAcross(across, 0.0) - 0.5 * (WhereAcross(across, -half) + WhereAcross(across, half));
    // A shift beyond a tenth of the run: a camera too far off yet to say.
    const cv::Point2d seen = std::fabs(shift) < 0.1
                                 ? pairing->middle[k] + 0.5 * shift * pairing->run[k]
                                 : pairing->middle[k];
    changed = std::max(changed, cv::norm(seen - pairing->seen[k]));
    pairing->seen[k] = seen;
  }
  return changed;
}

// Pairs again through the solved camera: each seen point's ray meets the plane of the view.
// Returns how far the farthest paired point moved, metres.
double PairThroughCamera(const CalibrationView& view, const cv::Mat& camera_matrix,
                         const cv::Mat& distortion, const cv::Mat& rvec, const cv::Mat& tvec,
                         LinePairing* pairing) {
  const std::vector<cv::Point2d> plane =
      OnViewPlane(pairing->seen, camera_matrix, distortion, rvec, tvec);
  double moved = 0.0;
  for (std::size_t k = 0; k < plane.size(); ++k) {
    const cv::Point2d& q = plane[k];
    if (!std::isfinite(q.x) || !std::isfinite(q.y)) continue;
    const cv::Point2d snapped = Snap(OnPlane(view.lines[pairing->line_of[k]]), q);
    moved = std::max(moved, cv::norm(snapped - pairing->paired[k]));
    pairing->paired[k] = snapped;
  }
  return moved;
}

// A view's pairing settled through the camera the other views have solved: its pose from its
// points (cv::solvePnP), its runs centred and its points paired again, until they stay.
LinePairing SettledPairing(const CalibrationView& view, LinePairing pairing,
                           const cv::Mat& camera_matrix, const cv::Mat& distortion) {
  std::fill(pairing.outlier.begin(), pairing.outlier.end(), 0);
  for (int round = 0; round < kMaxPairingRounds; ++round) {
    std::vector<cv::Point3d> object;
    std::vector<cv::Point2d> image;
    for (const CalibrationPoint& point : view.points) {
      object.emplace_back(point.x, point.y, 0.0);
      image.emplace_back(point.u, point.v);
    }
    for (std::size_t k = 0; k < pairing.seen.size(); ++k) {
      if (!pairing.used(k)) continue;
      object.emplace_back(pairing.paired[k].x, pairing.paired[k].y, 0.0);
      image.push_back(pairing.seen[k]);
    }
    cv::Mat rvec, tvec;
    if (object.size() < 4 || !cv::solvePnP(object, image, camera_matrix, distortion, rvec, tvec)) {
      break;
    }
    const double centred = CentreRuns(view, camera_matrix, distortion, rvec, tvec, &pairing);
    const double moved = PairThroughCamera(view, camera_matrix, distortion, rvec, tvec, &pairing);
    if (moved < kPairingSettledM && centred < kCentringSettledPx) break;
  }
  return pairing;
}

// The distortion terms a solve's flags leave free, as indices in the distortion vector.
std::vector<int> FreeDistortionTerms(int flags, int terms) {
  std::vector<int> free;
  const auto open = [&](int index, int fix) {
    if (index < terms && !(flags & fix)) free.push_back(index);
  };
  open(0, cv::CALIB_FIX_K1);
  open(1, cv::CALIB_FIX_K2);
  open(2, cv::CALIB_ZERO_TANGENT_DIST);
  open(3, cv::CALIB_ZERO_TANGENT_DIST);
  open(4, cv::CALIB_FIX_K3);
  if (flags & cv::CALIB_RATIONAL_MODEL) {
    open(5, cv::CALIB_FIX_K4);
    open(6, cv::CALIB_FIX_K5);
    open(7, cv::CALIB_FIX_K6);
  }
  return free;
}

// The camera and view poses after calibrateCamera, their deviations and the fit's RMS, as
// PolishAcrossLines leaves them.
struct Solution {
  cv::Mat camera_matrix, distortion;
  std::vector<cv::Mat> rvecs, tvecs;
  cv::Mat sd_intrinsics;  // fx, fy, cx, cy, then the distortion terms: OpenCV's order
  cv::Mat view_errors;    // RMS of each view's points
  double rms_px = 0.0;
};

// One view's rows of the polish: the residuals (pixels) and their derivatives by the
// intrinsics (fx, fy, cx, cy, every distortion term) and by the view's pose (rvec, tvec).
// A known point gives two rows (u, v); a point on a line one: its distance across the line's
// image, the projection of its paired plane point minus where it is seen, along the normal
// of the line's image there. The pairing slides along the line only, so holding it while
// differentiating leaves the derivative across the line exact to first order.
struct ViewRows {
  std::vector<double> residuals;
  cv::Mat by_intrinsics, by_pose;  // rows x (4 + terms), rows x 6
  int points = 0;
};

ViewRows RowsOf(const CalibrationView& view, const LinePairing& pairing, const Solution& solution,
                std::size_t i) {
  std::vector<cv::Point3d> object;
  for (const CalibrationPoint& point : view.points) object.emplace_back(point.x, point.y, 0.0);
  std::vector<std::size_t> line_points;
  for (std::size_t k = 0; k < pairing.seen.size(); ++k) {
    if (!pairing.used(k)) continue;
    line_points.push_back(k);
    const cv::Point2d direction = OnPlane(view.lines[pairing.line_of[k]]).direction;
    const cv::Point2d q = pairing.paired[k];
    object.emplace_back(q.x, q.y, 0.0);
    // A step along the line, for the direction of its image there.
    object.emplace_back(q.x + 1e-3 * direction.x, q.y + 1e-3 * direction.y, 0.0);
  }
  ViewRows rows;
  const int terms = solution.distortion.rows * solution.distortion.cols;
  const int rows_count =
      2 * static_cast<int>(view.points.size()) + static_cast<int>(line_points.size());
  rows.by_intrinsics = cv::Mat::zeros(rows_count, 4 + terms, CV_64F);
  rows.by_pose = cv::Mat::zeros(rows_count, 6, CV_64F);
  rows.points = static_cast<int>(view.points.size() + line_points.size());
  if (object.empty()) return rows;
  std::vector<cv::Point2d> image;
  cv::Mat jacobian;  // 2 per point: rvec, tvec, fx, fy, cx, cy, the distortion terms
  cv::projectPoints(object, solution.rvecs[i], solution.tvecs[i], solution.camera_matrix,
                    solution.distortion, image, jacobian);
  const auto add_row = [&](int row, int point, double nu, double nv, double residual) {
    rows.residuals.push_back(residual);
    for (int c = 0; c < 6; ++c) {
      rows.by_pose.at<double>(row, c) =
          nu * jacobian.at<double>(2 * point, c) + nv * jacobian.at<double>(2 * point + 1, c);
    }
    for (int c = 0; c < 4 + terms; ++c) {
      rows.by_intrinsics.at<double>(row, c) = nu * jacobian.at<double>(2 * point, 6 + c) +
                                              nv * jacobian.at<double>(2 * point + 1, 6 + c);
    }
  };
  int row = 0;
  for (std::size_t p = 0; p < view.points.size(); ++p) {
    const int point = static_cast<int>(p);
    add_row(row++, point, 1.0, 0.0, image[p].x - view.points[p].u);
    add_row(row++, point, 0.0, 1.0, image[p].y - view.points[p].v);
  }
  for (std::size_t j = 0; j < line_points.size(); ++j) {
    const int point = static_cast<int>(view.points.size() + 2 * j);
    const cv::Point2d tangent =
        image[static_cast<std::size_t>(point) + 1] - image[static_cast<std::size_t>(point)];
    const double length = cv::norm(tangent);
    const double nu = -tangent.y / length, nv = tangent.x / length;
    const cv::Point2d off = image[static_cast<std::size_t>(point)] - pairing.seen[line_points[j]];
    add_row(row++, point, nu, nv, nu * off.x + nv * off.y);
  }
  return rows;
}

// The unknowns of the polish (PolishAcrossLines): fx, fy, cx, cy, the free distortion terms,
// then each view's rvec and tvec.
class PolishUnknowns {
 public:
  PolishUnknowns(int flags, int terms, std::size_t views)
      : free_(FreeDistortionTerms(flags, terms)),
        intrinsics_(4 + static_cast<int>(free_.size())),
        count_(intrinsics_ + 6 * static_cast<int>(views)) {}

  int count() const { return count_; }

  // The normal equations J^T J and J^T r of every view's rows.
  void NormalEquations(const std::vector<ViewRows>& rows, cv::Mat* normal,
                       cv::Mat* gradient) const {
    *normal = cv::Mat::zeros(count_, count_, CV_64F);
    *gradient = cv::Mat::zeros(count_, 1, CV_64F);
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const cv::Mat columns = ViewColumns(rows[i]);
      const cv::Mat residuals(rows[i].residuals, false);
      const cv::Mat block = columns.t() * columns, pulled = columns.t() * residuals;
      // Where the view's columns (the intrinsics, its pose) sit among all the unknowns.
      std::vector<int> index;
      for (int c = 0; c < intrinsics_; ++c) index.push_back(c);
      for (int c = 0; c < 6; ++c) index.push_back(PoseAt(i) + c);
      for (std::size_t a = 0; a < index.size(); ++a) {
        gradient->at<double>(index[a]) += pulled.at<double>(static_cast<int>(a));
        for (std::size_t b = 0; b < index.size(); ++b) {
          normal->at<double>(index[a], index[b]) +=
              block.at<double>(static_cast<int>(a), static_cast<int>(b));
        }
      }
    }
  }

  // `from` moved by `step`.
  Solution Stepped(const Solution& from, const cv::Mat& step) const {
    Solution next = from;
    next.camera_matrix = from.camera_matrix.clone();
    next.distortion = from.distortion.clone();
    next.camera_matrix.at<double>(0, 0) += step.at<double>(0);
    next.camera_matrix.at<double>(1, 1) += step.at<double>(1);
    next.camera_matrix.at<double>(0, 2) += step.at<double>(2);
    next.camera_matrix.at<double>(1, 2) += step.at<double>(3);
    for (std::size_t t = 0; t < free_.size(); ++t) {
      next.distortion.at<double>(free_[t]) += step.at<double>(4 + static_cast<int>(t));
    }
    for (std::size_t i = 0; i < from.rvecs.size(); ++i) {
      next.rvecs[i] = from.rvecs[i] + step.rowRange(PoseAt(i), PoseAt(i) + 3);
      next.tvecs[i] = from.tvecs[i] + step.rowRange(PoseAt(i) + 3, PoseAt(i) + 6);
    }
    return next;
  }

  // The intrinsics' standard deviations in OpenCV's order (fx, fy, cx, cy, k1 ... k6; 0 for a
  // fixed term) from the normal equations and the residuals' variance.
  cv::Mat Deviations(const cv::Mat& normal, double variance) const {
    cv::Mat deviations = cv::Mat::zeros(4 + 8, 1, CV_64F), covariance;
    if (cv::invert(normal, covariance, cv::DECOMP_CHOLESKY) == 0.0) return deviations;
    for (int c = 0; c < intrinsics_; ++c) {
      const int at = c < 4 ? c : 4 + free_[static_cast<std::size_t>(c - 4)];
      deviations.at<double>(at) = std::sqrt(variance * covariance.at<double>(c, c));
    }
    return deviations;
  }

 private:
  int PoseAt(std::size_t view) const { return intrinsics_ + 6 * static_cast<int>(view); }

  // A view's derivatives by its unknowns: the free intrinsics, then its pose.
  cv::Mat ViewColumns(const ViewRows& rows) const {
    cv::Mat columns(static_cast<int>(rows.residuals.size()), intrinsics_ + 6, CV_64F);
    rows.by_intrinsics.colRange(0, 4).copyTo(columns.colRange(0, 4));
    for (std::size_t t = 0; t < free_.size(); ++t) {
      rows.by_intrinsics.col(4 + free_[t]).copyTo(columns.col(4 + static_cast<int>(t)));
    }
    rows.by_pose.copyTo(columns.colRange(intrinsics_, intrinsics_ + 6));
    return columns;
  }

  std::vector<int> free_;
  int intrinsics_, count_;
};

// Polishes the camera and the view poses on what the line points tell: their distances across
// their lines, each point free to slide along its line (Levenberg-Marquardt on the distances,
// each point paired again with its line after each step). calibrateCamera measures a line
// point's distance to a paired plane point fixed during each solve, so the pairing creeps
// along the lines over dozens of solves and stops short, the focal length a few tenths of a
// percent off under a strong lens; here it follows each step. Known points keep their two
// rows. The deviations come from this fit's normal equations.
void PolishAcrossLines(const std::vector<const CalibrationView*>& views, int flags,
                       std::vector<LinePairing>* pairings, Solution* solution) {
  const PolishUnknowns unknowns(flags, solution->distortion.rows * solution->distortion.cols,
                                views.size());
  // Pairs the points through `at` and gives their rows and their sum of squares.
  const auto pair_and_measure = [&](const Solution& at, std::vector<ViewRows>* rows) {
    double cost = 0.0;
    rows->clear();
    for (std::size_t i = 0; i < views.size(); ++i) {
      LinePairing& pairing = (*pairings)[i];
      CentreRuns(*views[i], at.camera_matrix, at.distortion, at.rvecs[i], at.tvecs[i], &pairing);
      PairThroughCamera(*views[i], at.camera_matrix, at.distortion, at.rvecs[i], at.tvecs[i],
                        &pairing);
      rows->push_back(RowsOf(*views[i], pairing, at, i));
      for (const double r : rows->back().residuals) cost += r * r;
    }
    return cost;
  };
  std::vector<ViewRows> rows;
  double cost = pair_and_measure(*solution, &rows);
  double damping = 1e-3;
  cv::Mat normal, gradient;
  for (int iteration = 0; iteration < kPolishIterations; ++iteration) {
    unknowns.NormalEquations(rows, &normal, &gradient);
    bool improved = false;
    for (; damping < 1e8; damping *= 10.0) {
      cv::Mat damped = normal.clone(), step;
      for (int d = 0; d < unknowns.count(); ++d) damped.at<double>(d, d) *= 1.0 + damping;
      if (!cv::solve(damped, -gradient, step, cv::DECOMP_CHOLESKY)) continue;
      const Solution next = unknowns.Stepped(*solution, step);
      const std::vector<LinePairing> before = *pairings;
      std::vector<ViewRows> next_rows;
      const double next_cost = pair_and_measure(next, &next_rows);
      if (next_cost > cost) {
        *pairings = before;
        continue;
      }
      improved = cost - next_cost > kPolishSettled * cost;
      *solution = next;
      rows = std::move(next_rows);
      cost = next_cost;
      damping = std::max(damping / 10.0, 1e-9);
      break;
    }
    if (!improved) break;
  }

  int residual_count = 0, points = 0;
  std::vector<double> view_errors;
  for (const ViewRows& view : rows) {
    double sum = 0.0;
    for (const double r : view.residuals) sum += r * r;
    residual_count += static_cast<int>(view.residuals.size());
    points += view.points;
    view_errors.push_back(view.points > 0 ? std::sqrt(sum / view.points) : 0.0);
  }
  solution->rms_px = points > 0 ? std::sqrt(cost / points) : 0.0;
  solution->view_errors = cv::Mat(view_errors, true);
  unknowns.NormalEquations(rows, &normal, &gradient);
  solution->sd_intrinsics =
      residual_count > unknowns.count()
          ? unknowns.Deviations(normal, cost / (residual_count - unknowns.count()))
          : cv::Mat::zeros(4 + 8, 1, CV_64F);
}

// Marks as outliers the line points the solved camera leaves farther from their lines than
// kOutlierSigmas robust standard deviations of all of them (a speck beside a stripe, a
// shadow's edge), but never nearer than kOutlierFloorPx: noise alone stays. Every point is
// judged again each time, so that one judged by a camera not yet right comes back. Returns how
// many points changed sides.
int MarkOutliers(const std::vector<const CalibrationView*>& views, const cv::Mat& camera_matrix,
                 const cv::Mat& distortion, const std::vector<cv::Mat>& rvecs,
                 const std::vector<cv::Mat>& tvecs, std::vector<LinePairing>* pairings) {
  std::vector<std::vector<double>> residuals(views.size());
  std::vector<double> all;
  for (std::size_t i = 0; i < views.size(); ++i) {
    LinePairing& pairing = (*pairings)[i];
    if (pairing.seen.empty()) continue;
    std::vector<cv::Point3d> object;
    for (const cv::Point2d& q : pairing.paired) object.emplace_back(q.x, q.y, 0.0);
    std::vector<cv::Point2d> projected;
    cv::projectPoints(object, rvecs[i], tvecs[i], camera_matrix, distortion, projected);
    for (std::size_t k = 0; k < projected.size(); ++k) {
      residuals[i].push_back(cv::norm(projected[k] - pairing.seen[k]));
    }
    all.insert(all.end(), residuals[i].begin(), residuals[i].end());
  }
  if (all.empty()) return 0;
  const double limit = std::max(kOutlierFloorPx, kOutlierSigmas * 1.4826 * MedianInPlace(&all));
  int changed = 0;
  for (std::size_t i = 0; i < views.size(); ++i) {
    LinePairing& pairing = (*pairings)[i];
    for (std::size_t k = 0; k < pairing.seen.size(); ++k) {
      const char outlier = residuals[i][k] > limit ? 1 : 0;
      changed += outlier != pairing.outlier[k];
      pairing.outlier[k] = outlier;
    }
  }
  return changed;
}

// Marks the view whose points fit worst when they fit kViewOutlierRatio times worse than the
// median view's, and worse than kViewOutlierFloorPx: it disagrees with the others as a whole.
// `view_errors` are the solve's per-view RMS of the views `used` (indices in result->views).
bool MarkDisagreeingView(const cv::Mat& view_errors, const std::vector<std::size_t>& used,
                         CalibrationResult* result) {
  if (used.size() < 3) return false;
  std::vector<double> rms;
  for (std::size_t i = 0; i < used.size(); ++i) {
    rms.push_back(view_errors.at<double>(static_cast<int>(i)));
  }
  const std::size_t worst =
      static_cast<std::size_t>(std::max_element(rms.begin(), rms.end()) - rms.begin());
  std::vector<double> reordered = rms;
  const double median = MedianInPlace(&reordered);
  if (rms[worst] <= kViewOutlierFloorPx || rms[worst] <= kViewOutlierRatio * median) return false;
  result->views[used[worst]].rejected = "its points disagree with the other views' (RMS " +
                                        Fixed(rms[worst], 2) + " px, the views' median " +
                                        Fixed(median, 2) + " px)";
  return true;
}

// Throws, naming each view left out and why, when fewer than `min_views` are left.
void RequireEnoughViews(const CalibrationResult& result, std::size_t used, int min_views) {
  if (static_cast<int>(used) >= min_views) return;
  std::ostringstream message;
  message << used << " usable view" << (used == 1 ? "" : "s") << " of " << result.views.size()
          << ", at least " << min_views << " needed";
  for (const CalibrationViewReport& report : result.views) {
    if (!report.rejected.empty()) message << "\n  " << report.name << ": " << report.rejected;
  }
  throw std::runtime_error(message.str());
}

int SeenPoints(const CalibrationView& view) {
  std::size_t count = view.points.size();
  for (const CalibrationLine& line : view.lines) count += line.seen.size();
  return static_cast<int>(count);
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
  RequireOption(min_term_significance >= 0.0 && min_term_significance <= 10.0,
                "CalibrationOptions::min_term_significance", min_term_significance,
                "0 <= min_term_significance <= 10");
}

CalibrationResult Calibrate(const std::vector<CalibrationView>& views,
                            const CalibrationOptions& options) {
  options.Check();
  CalibrationResult result;
  std::vector<const CalibrationView*> used_views;
  std::vector<std::size_t> used;  // index in `views` of each view handed to the solver
  std::vector<LinePairing> pairings;
  for (std::size_t k = 0; k < views.size(); ++k) {
    const CalibrationView& view = views[k];
    CalibrationViewReport& report = result.views.emplace_back();
    report.name = view.name;
    report.points = SeenPoints(view);
    if (report.points < options.min_points_per_view) {
      report.rejected = std::to_string(report.points) + " target points (min_points_per_view = " +
                        std::to_string(options.min_points_per_view) + ")";
      continue;
    }
    LinePairing& pairing = pairings.emplace_back();
    if (!view.lines.empty()) {
      const std::optional<cv::Matx33d> homography = plane_lines::FirstHomography(view);
      if (!homography) {
        report.rejected = "fewer than four of its lines' crossings and its points are known";
        pairings.pop_back();
        continue;
      }
      pairing = PairThroughHomography(view, *homography);
    }
    used_views.push_back(&view);
    used.push_back(k);
  }
  RequireEnoughViews(result, used.size(), options.min_views);

  // OpenCV's model, k1, k2, p1, p2, k3 (and k4-k6 when asked), every term the views determine:
  // a term whose value is within min_term_significance standard deviations of zero is fixed
  // at zero and the camera solved again (a term the views cannot tell follows their noise, and
  // bends px, u0 to absorb it). k3 (and the rational terms) first, then p1 and p2 together.
  int flags = options.rational ? cv::CALIB_RATIONAL_MODEL : 0;
  if (!options.estimate_distortion) {
    flags |= cv::CALIB_FIX_K1 | cv::CALIB_FIX_K2 | cv::CALIB_FIX_K3 | cv::CALIB_ZERO_TANGENT_DIST;
  }
  cv::Mat camera_matrix, distortion = cv::Mat::zeros(options.rational ? 8 : 5, 1, CV_64F),
                         sd_intrinsics, sd_extrinsics, view_errors;
  std::vector<cv::Mat> rvecs, tvecs;
  std::vector<std::vector<cv::Point2f>> image_points;
  std::vector<std::vector<cv::Point3f>> object_points;
  const cv::TermCriteria stop(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-12);
  const bool any_lines =
      std::any_of(used_views.begin(), used_views.end(),
                  [](const CalibrationView* view) { return !view->lines.empty(); });
  // Each view's first pairing, from its homography: where the solve starts over when a view
  // is left out, so that nothing the left-out view did to the others (their points cut as
  // outliers, their pairing) remains.
  std::vector<LinePairing> first_pairings(views.size());  // by index in `views`
  for (std::size_t i = 0; i < used.size(); ++i) first_pairings[used[i]] = pairings[i];
  // The solver's points: the known points and the line points used, paired; every
  // `line_stride`-th line point of a view when it has more than `max_line_points`.
  const auto gather = [&](std::size_t max_line_points) {
    object_points.clear();
    image_points.clear();
    for (std::size_t i = 0; i < used_views.size(); ++i) {
      std::vector<cv::Point3f>& object = object_points.emplace_back();
      std::vector<cv::Point2f>& image = image_points.emplace_back();
      for (const CalibrationPoint& point : used_views[i]->points) {
        object.emplace_back(static_cast<float>(point.x), static_cast<float>(point.y), 0.0f);
        image.emplace_back(static_cast<float>(point.u), static_cast<float>(point.v));
      }
      const std::size_t line_points = pairings[i].kept();
      const std::size_t line_stride =
          line_points > max_line_points ? (line_points + max_line_points - 1) / max_line_points : 1;
      for (std::size_t k = 0, used_index = 0; k < pairings[i].seen.size(); ++k) {
        if (!pairings[i].used(k)) continue;
        if (used_index++ % line_stride != 0) continue;
        object.emplace_back(static_cast<float>(pairings[i].paired[k].x),
                            static_cast<float>(pairings[i].paired[k].y), 0.0f);
        image.emplace_back(static_cast<float>(pairings[i].seen[k].x),
                           static_cast<float>(pairings[i].seen[k].y));
      }
    }
  };
  // Views left out as disagreeing with the others, by index in `views`, and those let back in
  // once (see solve).
  std::vector<char> left_out_views(views.size(), 0), readmitted(views.size(), 0);
  // Each round solves the camera on the points as paired (calibrateCamera), polishes it with
  // the pairing following each step (PolishAcrossLines), then judges the views and points on
  // the polished camera: the lens is right there, so the points it bends most, near the
  // image's edges, are not taken for outliers (they would go first and bias k1 low).
  const auto settle = [&](int solve_flags, bool from_previous) {
    for (int round = 0;; ++round) {
      // A view that disagrees with the others as a whole (a stripe taken for another, a sheet
      // not flat or printed stretched) is left out: the outlier cut has left it too few
      // points, or its points fit far worse than the other views'.
      bool left_out = false;
      for (std::size_t i = used_views.size(); i-- > 0;) {
        const std::size_t points = used_views[i]->points.size() + pairings[i].kept();
        std::string& rejected = result.views[used[i]].rejected;
        if (rejected.empty() && static_cast<int>(points) >= options.min_points_per_view) continue;
        if (rejected.empty()) {
          rejected = "its points disagree with the other views' (" + std::to_string(points) +
                     " of " + std::to_string(result.views[used[i]].points) + " kept)";
        }
        left_out_views[used[i]] = 1;
        used_views.erase(used_views.begin() + static_cast<std::ptrdiff_t>(i));
        used.erase(used.begin() + static_cast<std::ptrdiff_t>(i));
        left_out = true;
      }
      RequireEnoughViews(result, used.size(), options.min_views);
      if (left_out) {
        pairings.clear();
        for (const std::size_t k : used) pairings.push_back(first_pairings[k]);
      }
      // calibrateCamera's time grows faster than its points: it starts the polish from a
      // share of each view's line points, the polish fits them all.
      gather(kSolverLinePointsPerView);
      const bool guess = (round > 0 && !left_out) || from_previous;
      result.rms_px = cv::calibrateCamera(
          object_points, image_points, cv::Size(options.width, options.height), camera_matrix,
          distortion, rvecs, tvecs, sd_intrinsics, sd_extrinsics, view_errors,
          guess ? solve_flags | cv::CALIB_USE_INTRINSIC_GUESS : solve_flags, stop);
      if (!any_lines) {
        if (MarkDisagreeingView(view_errors, used, &result)) continue;
        break;
      }
      Solution solution{camera_matrix, distortion,  rvecs,        tvecs,
                        sd_intrinsics, view_errors, result.rms_px};
      PolishAcrossLines(used_views, solve_flags, &pairings, &solution);
      camera_matrix = solution.camera_matrix;
      distortion = solution.distortion;
      rvecs = solution.rvecs;
      tvecs = solution.tvecs;
      sd_intrinsics = solution.sd_intrinsics;
      view_errors = solution.view_errors;
      result.rms_px = solution.rms_px;
      gather(std::numeric_limits<std::size_t>::max());
      // A view that disagrees as a whole goes first, before the point cut could whittle it
      // down to its points that happen to fit.
      if (MarkDisagreeingView(view_errors, used, &result)) continue;
      const int changed =
          MarkOutliers(used_views, camera_matrix, distortion, rvecs, tvecs, &pairings);
      if (changed == 0 || round + 1 >= kMaxJudgingRounds) break;
    }
  };
  // A view is judged against the others from the first round, while points still to be cut
  // and views still to be left out pull the lens: one that reaches far towards the image's
  // corners, where the lens is least sure, can fit worse then than it does in the end. Each view
  // left out so is let back in once, from the settled camera, and judged again; one that disagrees
  // still is left out for good.
  const auto solve = [&](int solve_flags, bool from_previous) {
    settle(solve_flags, from_previous);
    bool readmit = false;
    for (std::size_t k = 0; k < views.size(); ++k) {
      if (!left_out_views[k] || readmitted[k]) continue;
      readmitted[k] = 1;
      left_out_views[k] = 0;
      result.views[k].rejected.clear();
      const auto at = std::upper_bound(used.begin(), used.end(), k);
      const std::ptrdiff_t i = at - used.begin();
      used.insert(at, k);
      used_views.insert(used_views.begin() + i, &views[k]);
      // Its homography's pairing is far off where the lens bends most: it starts from the
      // pairing the settled camera gives it, as the others go on from theirs.
      first_pairings[k] = SettledPairing(views[k], first_pairings[k], camera_matrix, distortion);
      pairings.insert(pairings.begin() + i, first_pairings[k]);
      readmit = true;
    }
    if (readmit) settle(solve_flags, true);
  };
  solve(flags, false);
  if (options.estimate_distortion) {
    // (indices in OpenCV's order of the intrinsics' deviations: fx, fy, cx, cy, k1, k2, p1,
    // p2, k3, k4, k5, k6)
    struct Group {
      const char* names;
      std::vector<int> terms;  // in the distortion vector
      int fix;
    };
    std::vector<Group> groups;
    if (options.rational) {
      groups.push_back(
          {"k4, k5, k6", {5, 6, 7}, cv::CALIB_FIX_K4 | cv::CALIB_FIX_K5 | cv::CALIB_FIX_K6});
    }
    groups.push_back({"p1, p2", {2, 3}, cv::CALIB_ZERO_TANGENT_DIST});
    // k3 (r^6) is told from k2 only where the views reach well out: nearer the middle, the two
    // trade against each other and k3 is fixed.
    const double reach = Reach(image_points, camera_matrix);
    const double corner = std::sqrt(
        CornerRadius2(Lens::Pinhole(camera_matrix.at<double>(0, 0), camera_matrix.at<double>(1, 1),
                                    camera_matrix.at<double>(0, 2), camera_matrix.at<double>(1, 2)),
                      options.width, options.height));
    if (reach < kK3Reach * corner) {
      result.fixed_terms.push_back(
          "k3 fixed at 0: the views reach " + Fixed(100.0 * reach / corner, 0) +
          " % of the way to the image's corners, too little to tell r^6 from r^4 (" +
          Fixed(100.0 * kK3Reach, 0) + " % needed)");
      flags |= cv::CALIB_FIX_K3;
      distortion.at<double>(4) = 0.0;
      solve(flags, true);
    }
    for (const Group& group : groups) {
      bool significant = false;
      std::string values;
      for (const int term : group.terms) {
        const double value = distortion.at<double>(term), sd = sd_intrinsics.at<double>(4 + term);
        significant |= std::fabs(value) > options.min_term_significance * sd;
        values += (values.empty() ? "" : ", ") + Fixed(value, 5) + " +- " + Fixed(sd, 5);
      }
      if (significant) continue;
      result.fixed_terms.push_back(
          std::string(group.names) + " fixed at 0: the views do not tell " +
          (group.terms.size() == 1 ? "it" : "them") + " from 0 (" + values + "; " +
          Fixed(options.min_term_significance, 1) + " standard deviations needed)");
      flags |= group.fix;
      for (const int term : group.terms) distortion.at<double>(term) = 0.0;
      solve(flags, true);
    }
  }

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
  std::array<double, 8> coefficients{}, deviations{};
  for (int i = 0; i < distortion.rows * distortion.cols && i < 8; ++i) {
    coefficients[static_cast<std::size_t>(i)] = distortion.at<double>(i);
    deviations[static_cast<std::size_t>(i)] = sd_intrinsics.at<double>(4 + i);
  }
  result.camera = Lens::WithDistortion(px, py, u0, v0, Distortion::FromArray(coefficients));
  result.distortion_sd = Distortion::FromArray(deviations);
  result.px_sd = sd_intrinsics.at<double>(0);
  result.py_sd = sd_intrinsics.at<double>(1);
  result.u0_sd = sd_intrinsics.at<double>(2);
  result.v0_sd = sd_intrinsics.at<double>(3);
  if (result.camera.distorted()) {
    // ViSP's one-term model of the lens, as its camera XML holds it: its RMS over the same
    // points, the views where the full model put them.
    const Lens one_term = result.camera.ViSPCamera(options.width, options.height);
    double sum = 0.0;
    std::size_t count = 0;
    for (std::size_t i = 0; i < object_points.size(); ++i) {
      cv::Mat rotation;
      cv::Rodrigues(rvecs[i], rotation);
      for (std::size_t k = 0; k < object_points[i].size(); ++k) {
        const cv::Point3f& o = object_points[i][k];
        const cv::Mat c = rotation * (cv::Mat_<double>(3, 1) << o.x, o.y, o.z) + tvecs[i];
        const double z = c.at<double>(2);
        const Point2d p = one_term.Pixel(c.at<double>(0) / z, c.at<double>(1) / z);
        sum += std::pow(p.u - image_points[i][k].x, 2) + std::pow(p.v - image_points[i][k].y, 2);
        ++count;
      }
    }
    result.visp_rms_px = count > 0 ? std::sqrt(sum / static_cast<double>(count)) : 0.0;
  } else {
    result.visp_rms_px = result.rms_px;
  }

  if (result.px_sd > kLooseFocalFraction * px || result.py_sd > kLooseFocalFraction * py) {
    result.advice.push_back("px, py are known to +-" + Fixed(100.0 * result.px_sd / px, 2) +
                            " %: tilt the target more (30-45 deg), in different directions");
  }
  if (result.u0_sd > kLoosePrincipalPx || result.v0_sd > kLoosePrincipalPx) {
    result.advice.push_back("u0, v0 are known to +-" +
                            Fixed(std::max(result.u0_sd, result.v0_sd), 1) +
                            " px: add views tilted about both image axes");
  }
  if (result.camera.distorted()) {
    // The lens is known where the views saw the target; beyond, it is extrapolated, and a
    // polynomial may fold over before the image's corners.
    const double reach2 = std::pow(Reach(image_points, camera_matrix), 2);
    const double corner2 = CornerRadius2(result.camera, options.width, options.height);
    bool invertible = true;
    try {
      CheckInvertibleOver(result.camera, options.width, options.height, "lens");
    } catch (const std::invalid_argument&) {
      invertible = false;
    }
    if (!invertible || reach2 < kCoveredFraction * kCoveredFraction * corner2) {
      result.advice.push_back(
          "the views reach " + Fixed(100.0 * std::sqrt(reach2 / corner2), 0) +
          " % of the way to the image's corners" +
          (invertible ? std::string(": the lens beyond is extrapolated")
                      : std::string(" and the fitted lens folds over before them (pixels there "
                                    "have no ray)")) +
          ": add views with the target near the image's corners");
    }
  }
  if (result.distortion_sd.k1 > kLooseK1) {
    result.advice.push_back("the distortion is known to +-" + Fixed(result.distortion_sd.k1, 3) +
                            ": add views with the target near the image's corners");
  }
  return result;
}

}  // namespace oal
