#include "calibration/hand_eye.h"

#include <visp3/core/vpThetaUVector.h>
#include <visp3/core/vpTranslationVector.h>

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <stdexcept>

#include "base/angles.h"
#include "base/check.h"
#include "base/format.h"
#include "detector/line.h"  // kPi
#include "robots/robot.h"   // Distance

namespace oal {
namespace {

// Two stations closer than this are one: the arm did not move between them.
constexpr double kSameStationM = 1e-4;
constexpr double kSameStationRad = 1e-3;
// Beyond these the result says what to change.
constexpr double kWeakAxisSpreadDeg = 30.0;
constexpr double kLoosePairsMm = 2.0;
constexpr double kLoosePairsDeg = 0.5;

struct Motion {
  double angle_rad = 0.0;
  vpColVector axis;  // unit, when angle_rad > 0
};

// The end effector's rotation from station i to station j.
Motion RotationBetween(const vpHomogeneousMatrix& wMe_i, const vpHomogeneousMatrix& wMe_j) {
  const vpThetaUVector theta_u((wMe_i.inverse() * wMe_j).getRotationMatrix());
  Motion motion;
  motion.angle_rad = std::sqrt(theta_u.sumSquare());
  if (motion.angle_rad > 0.0) {
    motion.axis.resize(3);
    for (unsigned int k = 0; k < 3; ++k) motion.axis[k] = theta_u[k] / motion.angle_rad;
  }
  return motion;
}

// Angle between two axes regardless of their sense, degrees in [0, 90].
double AxisAngleDeg(const vpColVector& a, const vpColVector& b) {
  const double cosine = std::min(1.0, std::fabs(vpColVector::dotProd(a, b)));
  return std::acos(cosine) * kDegPerRad;
}

void CheckStationsDiffer(const std::vector<HandEyePair>& pairs) {
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    for (std::size_t j = i + 1; j < pairs.size(); ++j) {
      const PoseDistance moved = Distance(pairs[i].wMe, pairs[j].wMe);
      if (moved.translation_m < kSameStationM && moved.rotation_rad < kSameStationRad) {
        throw std::runtime_error("pairs " + std::to_string(i + 1) + " and " +
                                 std::to_string(j + 1) +
                                 " have the same end-effector pose: the arm did not move between "
                                 "them; take each pair at a station of its own");
      }
    }
  }
}

// The widest angle between the rotation axes of two moves that each turn at least
// min_rotation_deg; throws when the arm barely turned or turned about one axis.
double AxisSpreadDeg(const std::vector<HandEyePair>& pairs, double min_rotation_deg) {
  std::vector<vpColVector> axes;
  double largest_deg = 0.0;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    for (std::size_t j = i + 1; j < pairs.size(); ++j) {
      const Motion motion = RotationBetween(pairs[i].wMe, pairs[j].wMe);
      largest_deg = std::max(largest_deg, motion.angle_rad * kDegPerRad);
      if (motion.angle_rad * kDegPerRad >= min_rotation_deg) axes.push_back(motion.axis);
    }
  }
  if (axes.empty()) {
    throw std::runtime_error("the arm turned at most " + Fixed(largest_deg, 2) +
                             " deg between stations: turn it by at least " +
                             Fixed(min_rotation_deg, 1) +
                             " deg between views, about two different axes");
  }
  double spread_deg = 0.0;
  for (std::size_t i = 0; i < axes.size(); ++i) {
    for (std::size_t j = i + 1; j < axes.size(); ++j) {
      spread_deg = std::max(spread_deg, AxisAngleDeg(axes[i], axes[j]));
    }
  }
  if (spread_deg < min_rotation_deg) {
    throw std::runtime_error(
        "the arm turned about one axis only (the axes of its turns are within " +
        Fixed(spread_deg, 1) +
        " deg of each other): along that axis the camera's offset cannot be seen; turn the "
        "arm about a second axis too");
  }
  return spread_deg;
}

cv::Mat RotationOf(const vpHomogeneousMatrix& M) {
  cv::Mat rotation(3, 3, CV_64F);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) rotation.at<double>(i, j) = M[i][j];
  }
  return rotation;
}

cv::Mat TranslationOf(const vpHomogeneousMatrix& M) {
  return (cv::Mat_<double>(3, 1) << M[0][3], M[1][3], M[2][3]);
}

// OpenCV's dual-quaternion solver (Daniilidis): rotation and translation together.
vpHomogeneousMatrix Solve(const std::vector<HandEyePair>& pairs) {
  std::vector<cv::Mat> wRe, wte, cRo, cto;
  for (const HandEyePair& pair : pairs) {
    wRe.push_back(RotationOf(pair.wMe));
    wte.push_back(TranslationOf(pair.wMe));
    cRo.push_back(RotationOf(pair.cMo));
    cto.push_back(TranslationOf(pair.cMo));
  }
  cv::Mat eRc, etc;
  try {
    cv::calibrateHandEye(wRe, wte, cRo, cto, eRc, etc, cv::CALIB_HAND_EYE_DANIILIDIS);
  } catch (const cv::Exception& error) {
    throw std::runtime_error("the hand-eye solver failed on these pairs: " + error.msg);
  }
  vpHomogeneousMatrix eMc;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) eMc[i][j] = eRc.at<double>(i, j);
    eMc[i][3] = etc.at<double>(i);
  }
  // Re-orthonormalised through theta-u: the solver's matrix is orthonormal to ~1e-12 only.
  return vpHomogeneousMatrix(eMc.getTranslationVector(), vpThetaUVector(eMc.getRotationMatrix()));
}

void Residuals(const std::vector<HandEyePair>& pairs, HandEyeResult* result) {
  std::vector<vpHomogeneousMatrix> wMo;
  wMo.reserve(pairs.size());
  for (const HandEyePair& pair : pairs) wMo.push_back(pair.wMe * result->eMc * pair.cMo);
  result->wMo = vpHomogeneousMatrix::mean(wMo);
  double sum_mm2 = 0.0, sum_deg2 = 0.0;
  for (const vpHomogeneousMatrix& each : wMo) {
    const PoseDistance off = Distance(result->wMo, each);
    HandEyePairResidual residual;
    residual.translation_mm = off.translation_m * 1e3;
    residual.rotation_deg = off.rotation_rad * kDegPerRad;
    sum_mm2 += residual.translation_mm * residual.translation_mm;
    sum_deg2 += residual.rotation_deg * residual.rotation_deg;
    result->residuals.push_back(residual);
  }
  const double n = static_cast<double>(pairs.size());
  result->rms_translation_mm = std::sqrt(sum_mm2 / n);
  result->rms_rotation_deg = std::sqrt(sum_deg2 / n);
}

}  // namespace

void HandEyeOptions::Check() const {
  RequireOption(min_pairs >= 3 && min_pairs <= 10000, "HandEyeOptions::min_pairs", min_pairs,
                "3 <= min_pairs <= 10000");
  RequireOption(min_rotation_deg >= 1.0 && min_rotation_deg <= 90.0,
                "HandEyeOptions::min_rotation_deg", min_rotation_deg,
                "1 <= min_rotation_deg <= 90");
}

void HandEyeStationOptions::Check() const {
  RequireOption(count >= 4 && count <= 100, "HandEyeStationOptions::count", count,
                "4 <= count <= 100");
  RequireOption(tilt_deg >= 2.0 && tilt_deg <= 45.0, "HandEyeStationOptions::tilt_deg", tilt_deg,
                "2 <= tilt_deg <= 45");
  RequireOption(roll_deg >= 0.0 && roll_deg <= 90.0, "HandEyeStationOptions::roll_deg", roll_deg,
                "0 <= roll_deg <= 90");
}

HandEyeResult CalibrateHandEye(const std::vector<HandEyePair>& pairs,
                               const HandEyeOptions& options) {
  options.Check();
  if (static_cast<int>(pairs.size()) < options.min_pairs) {
    throw std::runtime_error(std::to_string(pairs.size()) +
                             " pairs: the hand-eye transform needs at least " +
                             std::to_string(options.min_pairs) +
                             " (stations where the robot stood still and the target was seen)");
  }
  CheckStationsDiffer(pairs);
  HandEyeResult result;
  result.axis_spread_deg = AxisSpreadDeg(pairs, options.min_rotation_deg);

  result.eMc = Solve(pairs);
  Residuals(pairs, &result);

  if (result.axis_spread_deg < kWeakAxisSpreadDeg) {
    result.advice.push_back("the arm's turns are about axes only " +
                            Fixed(result.axis_spread_deg, 0) +
                            " deg apart: tilt the camera in more directions");
  }
  if (result.rms_translation_mm > kLoosePairsMm || result.rms_rotation_deg > kLoosePairsDeg) {
    result.advice.push_back(
        "through this eMc the pairs place the target " + Fixed(result.rms_translation_mm, 1) +
        " mm and " + Fixed(result.rms_rotation_deg, 2) +
        " deg apart (RMS): check that the target did not move, that each pose was read with the "
        "arm still, and the camera's calibration");
  }
  return result;
}

std::vector<vpHomogeneousMatrix> HandEyeStations(const vpHomogeneousMatrix& wMe,
                                                 const vpHomogeneousMatrix& eMc_guess,
                                                 const vpHomogeneousMatrix& cMo,
                                                 const HandEyeStationOptions& options) {
  options.Check();
  const vpHomogeneousMatrix wMc = wMe * eMc_guess;
  const vpTranslationVector pivot = cMo.getTranslationVector();
  vpHomogeneousMatrix to_pivot, from_pivot;
  to_pivot.buildFrom(pivot, vpThetaUVector(0, 0, 0));
  from_pivot = to_pivot.inverse();
  // Tilt directions by the golden angle: any first few stations already spread around the
  // optical axis. Tilts and rolls alternate between full and part size, so that the moves
  // between stations turn about many axes and by many angles.
  const double golden_rad = kPi * (3.0 - std::sqrt(5.0));
  const double roll_pattern[] = {1.0, -1.0, 0.5, -0.5};
  std::vector<vpHomogeneousMatrix> stations;
  for (int k = 0; k < options.count; ++k) {
    const double direction = golden_rad * k;
    const double tilt = options.tilt_deg / kDegPerRad * (k % 2 == 0 ? 1.0 : 0.6);
    const double roll = options.roll_deg / kDegPerRad * roll_pattern[k % 4];
    const vpHomogeneousMatrix tilt_about(0, 0, 0, tilt * std::cos(direction),
                                         tilt * std::sin(direction), 0);
    const vpHomogeneousMatrix roll_about(0, 0, 0, 0, 0, roll);
    // Turned about the pivot: the pivot keeps its place in the camera's view.
    const vpHomogeneousMatrix cMc_station = to_pivot * roll_about * tilt_about * from_pivot;
    stations.push_back(wMc * cMc_station * eMc_guess.inverse());
  }
  return stations;
}

}  // namespace oal
