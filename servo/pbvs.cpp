#include "servo/pbvs.h"

#include <visp3/core/vpExponentialMap.h>
#include <visp3/core/vpMath.h>
#include <visp3/visual_features/vpFeatureThetaU.h>
#include <visp3/visual_features/vpFeatureTranslation.h>
#include <visp3/vs/vpAdaptiveGain.h>
#include <visp3/vs/vpServo.h>

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "detector/options.h"

namespace oal {
namespace {

// The ceres-style message of every Options::Check() (detector/options.h).
void Require(bool ok, const char* field, double value, const char* constraint) {
  RequireOption(ok, std::string("ServoOptions::") + field, value, constraint);
}

vpAdaptiveGain GainOf(const ServoOptions& options) {
  if (options.adaptive_gain) {
    return vpAdaptiveGain(options.gain_at_zero, options.gain_at_infinity,
                          options.gain_slope_at_zero);
  }
  return vpAdaptiveGain(options.gain);
}

}  // namespace

std::string ToString(ServoMode mode) {
  switch (mode) {
    case ServoMode::kPointAndGo:
      return "point-and-go";
    case ServoMode::kExponential:
      return "exponential";
    case ServoMode::kVelocity:
      return "velocity";
  }
  return "unknown";
}

std::string ToString(ServoStatus status) {
  switch (status) {
    case ServoStatus::kRunning:
      return "running";
    case ServoStatus::kConverged:
      return "converged";
  }
  return "unknown";
}

ServoMode ServoModeFromString(const std::string& name) {
  for (ServoMode mode : {ServoMode::kPointAndGo, ServoMode::kExponential, ServoMode::kVelocity}) {
    if (ToString(mode) == name) return mode;
  }
  throw std::invalid_argument("servo mode '" + name +
                              "': expected one of point-and-go, exponential, velocity");
}

void ServoOptions::Check() const {
  Require(delta > 0.0 && delta <= 1.0, "delta", delta, "in (0, 1]");
  Require(gain > 0.0 && gain <= 1e3, "gain", gain, "in (0, 1e3]");
  Require(gain_at_zero > 0.0 && gain_at_zero <= 1e3, "gain_at_zero", gain_at_zero, "in (0, 1e3]");
  Require(gain_at_infinity > 0.0 && gain_at_infinity <= 1e3, "gain_at_infinity", gain_at_infinity,
          "in (0, 1e3]");
  Require(gain_at_zero >= gain_at_infinity, "gain_at_zero", gain_at_zero, ">= gain_at_infinity");
  Require(gain_slope_at_zero > 0.0 && gain_slope_at_zero <= 1e6, "gain_slope_at_zero",
          gain_slope_at_zero, "in (0, 1e6]");
  Require(translation_tolerance_m > 0.0 && translation_tolerance_m <= 10.0,
          "translation_tolerance_m", translation_tolerance_m, "in (0, 10]");
  Require(rotation_tolerance_deg > 0.0 && rotation_tolerance_deg <= 180.0, "rotation_tolerance_deg",
          rotation_tolerance_deg, "in (0, 180]");
}

namespace {

// The task for cMo, cdMo; the velocity (interaction matrix and its pseudo-inverse, most of the
// cost) only when asked: the position laws need the error alone.
PbvsTaskState Evaluate(const vpHomogeneousMatrix& cMo, const vpHomogeneousMatrix& cdMo,
                       const ServoOptions& options, bool with_velocity) {
  options.Check();
  PbvsTaskState state;
  state.cdMc = cdMo * cMo.inverse();

  // ViSP's PBVS (example servoSimuThetaUCamVelocity / vpFeatureTranslation docs): s = (cd_t_c,
  // θu(cdRc)), s* = 0 (added by addFeature(s) as a zeroed duplicate), L current.
  vpFeatureTranslation t(vpFeatureTranslation::cdMc);
  vpFeatureThetaU tu(vpFeatureThetaU::cdRc);
  t.buildFrom(state.cdMc);
  tu.buildFrom(state.cdMc);
  vpServo task;
  task.setServo(vpServo::EYEINHAND_CAMERA);
  task.setInteractionMatrixType(vpServo::CURRENT);
  const vpAdaptiveGain gain = GainOf(options);
  task.setLambda(gain);
  task.addFeature(t);
  task.addFeature(tu);
  if (with_velocity) {
    state.velocity = task.computeControlLaw();
    state.error = task.getError();
  } else {
    state.error = task.computeError();
    state.velocity = vpColVector(6, 0.0);
  }
  state.gain = gain(state.error);

  state.translation_error_m = std::sqrt(vpMath::sqr(state.error[0]) + vpMath::sqr(state.error[1]) +
                                        vpMath::sqr(state.error[2]));
  state.rotation_error_rad = std::sqrt(vpMath::sqr(state.error[3]) + vpMath::sqr(state.error[4]) +
                                       vpMath::sqr(state.error[5]));
  return state;
}

}  // namespace

PbvsTaskState EvaluatePbvsTask(const vpHomogeneousMatrix& cMo, const vpHomogeneousMatrix& cdMo,
                               const ServoOptions& options) {
  return Evaluate(cMo, cdMo, options, true);
}

vpColVector Se3Log(const vpHomogeneousMatrix& M) {
  return vpExponentialMap::inverse(M, 1.0);
}

vpHomogeneousMatrix Se3Exp(const vpColVector& xi) {
  return vpExponentialMap::direct(xi, 1.0);
}

ServoStep ComputeServoStep(const vpHomogeneousMatrix& cMo, const vpHomogeneousMatrix& cdMo,
                           const ServoOptions& options) {
  const PbvsTaskState task = Evaluate(cMo, cdMo, options, options.mode == ServoMode::kVelocity);
  ServoStep step;
  step.mode = options.mode;
  step.translation_error_m = task.translation_error_m;
  step.rotation_error_rad = task.rotation_error_rad;

  std::ostringstream what;
  what << "error " << task.translation_error_m * 1e3 << " mm, "
       << vpMath::deg(task.rotation_error_rad) << " deg";
  if (task.translation_error_m <= options.translation_tolerance_m &&
      vpMath::deg(task.rotation_error_rad) <= options.rotation_tolerance_deg) {
    step.status = ServoStatus::kConverged;
    step.message = "converged: " + what.str() + " within the tolerances";
    return step;
  }
  step.status = ServoStatus::kRunning;
  const vpHomogeneousMatrix cMcd = task.cdMc.inverse();
  switch (options.mode) {
    case ServoMode::kPointAndGo:
      step.c_T_cnew = cMcd;
      step.twist = Se3Log(cMcd);
      step.message = "point-and-go: move by the whole displacement, " + what.str();
      break;
    case ServoMode::kExponential:
      step.twist = options.delta * Se3Log(cMcd);
      step.c_T_cnew = Se3Exp(step.twist);
      step.message = "exponential: move by exp(delta log(cMcd)), " + what.str();
      break;
    case ServoMode::kVelocity:
      step.twist = task.velocity;
      step.gain = task.gain;
      step.message = "velocity: -lambda L^-1 e, " + what.str();
      break;
  }
  return step;
}

}  // namespace oal
