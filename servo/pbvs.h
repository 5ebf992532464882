// Position-based visual servoing of an eye-in-hand camera to a goal pose (paper, section 4):
// three laws on one vpServo PBVS task.
//
// Frames (docs/ARCHITECTURE.md): c = current camera, cd = desired (goal) camera, o = target.
//   cMo   the current pose of the target in the camera (estimated by servo/pose.h),
//   cdMo  the goal: the target as the camera should see it at the goal,
//   cdMc  = cdMo · cMo⁻¹, the current camera in the goal camera frame; cMcd = cdMc⁻¹ is the
//         displacement to the goal expressed in the current camera frame.
//
// The task (EvaluatePbvsTask) is ViSP's PBVS: vpServo::EYEINHAND_CAMERA, interaction matrix
// vpServo::CURRENT, features s = (vpFeatureTranslation(cdMc), vpFeatureThetaU(cdMc)) with
// s* = 0, so the error is e = (cd_t_c, θu(cdRc)): |e_t| is the distance between the camera
// centres (metres), |e_θu| the rotation angle between the cameras (radians). Its velocity,
// -λ·L⁻¹·e, is v = λ·c_t_cd, ω = λ·θu(cRcd): translation and rotation decoupled.
//
// The laws (ServoMode), given cMo and cdMo, return the command for one step (ServoStep):
//   kPointAndGo   c_T_cnew = cMcd: the new camera pose in the current camera frame is the goal,
//                 "move by all of it" (gain 1, one position move). Re-estimate, repeat.
//   kExponential  Eq. 6, cT(k+1) = cT(k)·exp(Δ·ξ), ξ = log(cMcd) ∈ se(3) the exact SE(3)
//                 logarithm (Se3Log): c_T_cnew = exp(Δ·ξ), Δ ∈ (0, 1]. Moves along the screw
//                 (geodesic) from the current pose to the goal; Δ = 1 is point-and-go.
//                 This differs from vpServo's twist whenever there is rotation: ξ's
//                 translational part is V(ω)⁻¹·c_t_cd (V the left Jacobian of SO(3)), the
//                 task's is c_t_cd. With pure translation they are equal.
//   kVelocity     the task's velocity (v, ω) = -λ·L⁻¹·e in the camera frame (m/s, rad/s),
//                 constant λ or vpAdaptiveGain(λ0, λ∞, slope) of |e|∞, for robots driven in
//                 velocity. The caller integrates it over its period (exp(v·dt)) and applies
//                 its velocity limits (saturation) before sending it.
// Which to use: position-controlled arms (the paper's Scorbot) take kExponential with Δ < 1,
// which shrinks a pose estimate's error with every step (the error of the relative pose goes to
// zero at the goal) and does not overshoot by an estimate's overestimated displacement as
// point-and-go does; kPointAndGo when the estimate is trusted and moves are expensive;
// kVelocity for robots driven in velocity at a fixed rate.
//
// Convergence: both |e_t| ≤ translation_tolerance_m and the angle ≤ rotation_tolerance_deg,
// measured on the estimated cdMc; the command is then the identity / zero velocity.
#pragma once

#include <visp3/core/vpColVector.h>
#include <visp3/core/vpHomogeneousMatrix.h>

#include <string>

namespace oal {

enum class ServoMode { kPointAndGo, kExponential, kVelocity };
enum class ServoStatus {
  kRunning,    ///< the command moves the camera towards the goal
  kConverged,  ///< within both tolerances; the command is the identity / zero velocity
};

/// The one place where these enums meet strings ("point-and-go", "exponential", "velocity";
/// "running", "converged").
std::string ToString(ServoMode mode);
std::string ToString(ServoStatus status);
/// Inverse of ToString(ServoMode); throws std::invalid_argument listing the accepted names.
ServoMode ServoModeFromString(const std::string& name);

struct ServoOptions {
  ServoMode mode = ServoMode::kExponential;
  /// kExponential: fraction Δ of the twist to the goal moved per step (Eq. 6; the paper used
  /// 0.8). Range (0, 1].
  double delta = 0.8;
  /// kVelocity: constant gain λ, 1/s, used when adaptive_gain is false. Range (0, 1e3].
  double gain = 1.0;
  /// kVelocity: true uses vpAdaptiveGain(gain_at_zero, gain_at_infinity, gain_slope_at_zero)
  /// of the error's infinity norm instead of `gain`.
  bool adaptive_gain = false;
  double gain_at_zero = 4.0;         ///< λ(0), 1/s. Range (0, 1e3], ≥ gain_at_infinity.
  double gain_at_infinity = 0.4;     ///< λ(∞), 1/s. Range (0, 1e3].
  double gain_slope_at_zero = 30.0;  ///< λ'(0) magnitude. Range (0, 1e6].
  /// Converged when the distance between the current and goal camera centres is at most this,
  /// metres. Range (0, 10].
  double translation_tolerance_m = 0.001;
  /// ... and the rotation angle between them is at most this, degrees. Range (0, 180].
  double rotation_tolerance_deg = 0.1;

  /// Throws std::invalid_argument naming the field, its value and the violated constraint.
  void Check() const;
};

/// The PBVS task evaluated for one pose: the error and vpServo's velocity for gain λ.
struct PbvsTaskState {
  vpHomogeneousMatrix cdMc;  ///< cdMo · cMo⁻¹
  vpColVector error;         ///< e = (cd_t_c, θu(cdRc)), 6 values, metres and radians
  vpColVector velocity;      ///< -λ·L⁻¹·e = (v, ω) in the camera frame, m/s and rad/s
  double gain = 0.0;         ///< λ used, 1/s
  double translation_error_m = 0.0;  ///< |cd_t_c|
  double rotation_error_rad = 0.0;   ///< |θu|, in [0, π]
};

/// Builds the vpServo task (see the file comment) for cMo, cdMo and evaluates it with the gain
/// of `options` (constant `gain` or the adaptive gain). Every law uses it. Throws
/// std::invalid_argument if the options fail Check().
PbvsTaskState EvaluatePbvsTask(const vpHomogeneousMatrix& cMo, const vpHomogeneousMatrix& cdMo,
                               const ServoOptions& options);

/// The exact SE(3) logarithm ξ = (v, ω) of M (ViSP's twist order, dt = 1):
/// exp(ξ) = M, ω = θu(R), v = V(ω)⁻¹·t with V = I + (1-cosθ)/θ²·[ω]× + (θ-sinθ)/θ³·[ω]×².
/// vpExponentialMap::inverse(M, 1.0), which computes exactly this for θ < π.
vpColVector Se3Log(const vpHomogeneousMatrix& M);
/// exp(ξ) for ξ = (v, ω): vpExponentialMap::direct(ξ, 1.0).
vpHomogeneousMatrix Se3Exp(const vpColVector& xi);

struct ServoStep {
  ServoStatus status = ServoStatus::kRunning;
  std::string message;  ///< why it stopped or what it commands, for logs
  ServoMode mode = ServoMode::kExponential;
  /// kPointAndGo, kExponential: the new camera pose in the current camera frame (move the
  /// camera by it: wMc_new = wMc · c_T_cnew). Identity in kVelocity and when converged.
  vpHomogeneousMatrix c_T_cnew;
  /// The twist commanded, (v, ω) in the current camera frame: kExponential Δ·log(cMcd) (per
  /// step, so c_T_cnew = exp(twist)); kPointAndGo log(cMcd); kVelocity the velocity in m/s
  /// and rad/s, before the caller's saturation. Zero when converged.
  vpColVector twist = vpColVector(6, 0.0);
  double gain = 0.0;                 ///< kVelocity: λ used, 1/s; 0 otherwise
  double translation_error_m = 0.0;  ///< before the step, from the estimated cMo
  double rotation_error_rad = 0.0;   ///< before the step, from the estimated cMo
};

/// One step of the law options.mode from the estimated cMo to the goal cdMo. Never throws for
/// a pose; throws std::invalid_argument if the options fail Check().
ServoStep ComputeServoStep(const vpHomogeneousMatrix& cMo, const vpHomogeneousMatrix& cdMo,
                           const ServoOptions& options);

}  // namespace oal
