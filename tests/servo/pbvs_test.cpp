// The PBVS laws (servo/pbvs.h) in pure simulation: a perfect pose "sensor" (the camera pose is
// updated by the commanded steps and cMo recomputed exactly, or perturbed by a fixed error),
// from 100 seeded random start poses and from the paper's Table 3 scenario; and the difference
// between vpServo's decoupled PBVS twist and the se(3) logarithm that Eq. 6 uses.
#include "servo/pbvs.h"

#include <gtest/gtest.h>
#include <visp3/core/vpExponentialMap.h>
#include <visp3/core/vpMath.h>
#include <visp3/core/vpRotationMatrix.h>
#include <visp3/core/vpThetaUVector.h>
#include <visp3/core/vpTranslationVector.h>

#include <cmath>
#include <functional>
#include <iostream>
#include <random>
#include <stdexcept>

namespace oal {
namespace {

constexpr double kTolTranslationM = 0.001;  // the servo tolerance, 1 mm
constexpr double kTolRotationDeg = 0.1;     // and 0.1 deg
constexpr double kExact = 1e-9;             // floating-point identities
constexpr int kTrials = 100;

using Estimator = std::function<vpHomogeneousMatrix(const vpHomogeneousMatrix&)>;

vpHomogeneousMatrix Perfect(const vpHomogeneousMatrix& cMo) {
  return cMo;
}

double MaxAbsDiff(const vpHomogeneousMatrix& a, const vpHomogeneousMatrix& b) {
  double worst = 0.0;
  for (unsigned i = 0; i < 4; ++i)
    for (unsigned j = 0; j < 4; ++j) worst = std::max(worst, std::abs(a[i][j] - b[i][j]));
  return worst;
}

double MaxAbsDiff(const vpColVector& a, const vpColVector& b) {
  double worst = 0.0;
  for (unsigned i = 0; i < a.size(); ++i) worst = std::max(worst, std::abs(a[i] - b[i]));
  return worst;
}

vpColVector Part(const vpColVector& xi, unsigned first) {
  vpColVector out(3);
  for (unsigned i = 0; i < 3; ++i) out[i] = xi[first + i];
  return out;
}

ServoOptions Options(ServoMode mode) {
  ServoOptions options;
  options.mode = mode;
  options.translation_tolerance_m = kTolTranslationM;
  options.rotation_tolerance_deg = kTolRotationDeg;
  return options;
}

struct RunResult {
  int moves = 0;  ///< commands sent before the law reported kConverged
  bool converged = false;
  double true_translation_error_m = 0.0;  ///< at the end, from the true poses
  double true_rotation_error_deg = 0.0;
};

// Closed loop: wMc is moved by each command (position modes: wMc·c_T_cnew; velocity mode:
// wMc·exp(v·dt), as vpSimulatorCamera does). The goal given to the law is the estimate of the
// true goal pose ("taught" from the estimator at the goal), so a consistent estimator error
// vanishes at the goal.
RunResult RunLoop(vpHomogeneousMatrix wMc, const vpHomogeneousMatrix& wMo,
                  const vpHomogeneousMatrix& cdMo, const ServoOptions& options,
                  const Estimator& estimate, int max_moves, double dt = 0.0,
                  bool print_table3 = false) {
  RunResult result;
  const vpHomogeneousMatrix goal = estimate(cdMo);
  for (;;) {
    if (print_table3) {
      // Table 3's columns: wRc = Rx(pi) Rx(pitch) Rz(roll), see Table3Pose.
      const vpRotationMatrix M = vpRotationMatrix(vpThetaUVector(-M_PI, 0, 0)) *
                                 vpHomogeneousMatrix(wMc).getRotationMatrix();
      std::cout << "  " << result.moves << "  X " << wMc[0][3] * 1e3 << "  Y " << wMc[1][3] * 1e3
                << "  Z " << wMc[2][3] * 1e3 << "  pitch "
                << vpMath::deg(std::atan2(-M[1][2], M[2][2])) << "  roll "
                << vpMath::deg(std::atan2(-M[0][1], M[0][0])) << "\n";
    }
    const vpHomogeneousMatrix cMo = wMc.inverse() * wMo;
    const ServoStep step = ComputeServoStep(estimate(cMo), goal, options);
    if (step.status == ServoStatus::kConverged) {
      result.converged = true;
      break;
    }
    if (result.moves >= max_moves) break;
    ++result.moves;
    wMc = options.mode == ServoMode::kVelocity ? wMc * vpExponentialMap::direct(step.twist, dt)
                                               : wMc * step.c_T_cnew;
  }
  const vpHomogeneousMatrix cdMc = cdMo * (wMc.inverse() * wMo).inverse();
  result.true_translation_error_m = cdMc.getTranslationVector().frobeniusNorm();
  result.true_rotation_error_deg = vpMath::deg(vpThetaUVector(cdMc).getTheta());
  return result;
}

// Target frame = world. The goal camera sees the target 0.5 m ahead, axes aligned.
vpHomogeneousMatrix RandomGoal() {
  return vpHomogeneousMatrix(0.0, 0.0, 0.5, 0.0, 0.0, 0.0);
}

// A start camera 0.3-0.8 m from the target origin, within 40 deg of the goal's line of sight,
// its orientation up to 30 deg off the goal's (about a random axis).
vpHomogeneousMatrix RandomStart_wMc(std::mt19937& rng, const vpHomogeneousMatrix& cdMo) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0), distance(0.3, 0.8),
      angle(0.0, vpMath::rad(30.0)), cone(0.0, vpMath::rad(40.0)), turn(0.0, 2 * M_PI);
  const double a = cone(rng), b = turn(rng);
  const double d = distance(rng);
  const vpTranslationVector centre(d * std::sin(a) * std::cos(b), d * std::sin(a) * std::sin(b),
                                   -d * std::cos(a));
  vpColVector axis(3);
  do {
    for (unsigned i = 0; i < 3; ++i) axis[i] = unit(rng);
  } while (axis.frobeniusNorm() < 0.1);
  axis.normalize();
  const vpColVector tu = angle(rng) * axis;
  const vpRotationMatrix oRc =
      cdMo.inverse().getRotationMatrix() * vpRotationMatrix(vpThetaUVector(tu[0], tu[1], tu[2]));
  return vpHomogeneousMatrix(centre, oRc);
}

// ---- vpServo's twist vs the se(3) log --------------------------------------------------------

// The closed-form inverse of the left Jacobian, written independently of ViSP.
vpColVector ReferenceLog(const vpHomogeneousMatrix& M) {
  const vpThetaUVector tu(M.getRotationMatrix());
  const double theta = tu.getTheta();
  const vpMatrix W = vpColVector::skew(vpColVector(tu));
  vpMatrix Vinv(3, 3);
  Vinv.eye();
  Vinv -= 0.5 * W;
  if (theta > 1e-8) {
    Vinv += (1.0 - theta * std::sin(theta) / (2.0 * (1.0 - std::cos(theta)))) / (theta * theta) *
            (W * W);
  }
  const vpColVector v = Vinv * vpColVector(M.getTranslationVector());
  vpColVector xi(6);
  for (unsigned i = 0; i < 3; ++i) {
    xi[i] = v[i];
    xi[3 + i] = tu[i];
  }
  return xi;
}

TEST(Se3Log, IsTheTrueLogarithm) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 1000; ++trial) {
    vpColVector axis(3);
    for (unsigned i = 0; i < 3; ++i) axis[i] = u(rng);
    axis.normalize();
    const vpColVector tu = (1.5 + 1.5 * u(rng)) * axis;  // angles in [0, 3) rad
    const vpHomogeneousMatrix M(vpTranslationVector(u(rng), u(rng), u(rng)),
                                vpThetaUVector(tu[0], tu[1], tu[2]));
    const vpColVector xi = Se3Log(M);
    EXPECT_LT(MaxAbsDiff(xi, ReferenceLog(M)), kExact) << "trial " << trial;
    EXPECT_LT(MaxAbsDiff(Se3Exp(xi), M), kExact) << "trial " << trial;
  }
}

TEST(PbvsTask, VpServoTwistIsNotTheLogWhenRotating) {
  const vpHomogeneousMatrix cdMo(0.0, 0.0, 0.5, 0.0, 0.0, 0.0);
  const vpHomogeneousMatrix cMo(0.1, -0.05, 0.6, vpMath::rad(10), vpMath::rad(-5), vpMath::rad(20));
  ServoOptions options = Options(ServoMode::kVelocity);
  options.gain = 1.0;
  const PbvsTaskState task = EvaluatePbvsTask(cMo, cdMo, options);
  const vpHomogeneousMatrix cMcd = task.cdMc.inverse();
  const vpColVector log = Se3Log(cMcd);

  // The task's twist: v = c_t_cd, ω = θu(cRcd): same rotation as the log, not the same
  // translation; integrated over unit time it does not reach the goal.
  EXPECT_LT(MaxAbsDiff(Part(task.velocity, 3), Part(log, 3)), kExact);
  EXPECT_LT(MaxAbsDiff(Part(task.velocity, 0), vpColVector(cMcd.getTranslationVector())), kExact);
  const double v_difference = (Part(task.velocity, 0) - Part(log, 0)).frobeniusNorm();
  std::cout << "vpServo v vs log v differ by " << v_difference * 1e3 << " mm/s (rotation "
            << vpMath::deg(task.rotation_error_rad) << " deg); exp(vpServo twist) misses the "
            << "goal by "
            << (Se3Exp(task.velocity).inverse() * cMcd).getTranslationVector().frobeniusNorm() * 1e3
            << " mm\n";
  EXPECT_GT(v_difference, 0.01);
  EXPECT_GT((Se3Exp(task.velocity).inverse() * cMcd).getTranslationVector().frobeniusNorm(), 0.005);
  EXPECT_LT(MaxAbsDiff(Se3Exp(log), cMcd), kExact);
}

TEST(PbvsTask, VpServoTwistIsTheLogForPureTranslation) {
  const vpHomogeneousMatrix cdMo(0.0, 0.0, 0.5, 0.0, 0.0, 0.0);
  const vpHomogeneousMatrix cMo(0.1, -0.05, 0.6, 0.0, 0.0, 0.0);
  ServoOptions options = Options(ServoMode::kVelocity);
  options.gain = 1.0;
  const PbvsTaskState task = EvaluatePbvsTask(cMo, cdMo, options);
  EXPECT_LT(MaxAbsDiff(task.velocity, Se3Log(task.cdMc.inverse())), kExact);
  EXPECT_NEAR(task.translation_error_m, std::sqrt(0.1 * 0.1 + 0.05 * 0.05 + 0.1 * 0.1), kExact);
  EXPECT_NEAR(task.rotation_error_rad, 0.0, kExact);
}

TEST(ExponentialLaw, MovesAlongTheScrewGeodesic) {
  const vpHomogeneousMatrix cMcd(0.2, -0.1, 0.15, vpMath::rad(20), vpMath::rad(-10),
                                 vpMath::rad(25));
  const vpColVector xi = Se3Log(cMcd);
  // Two half steps compose to the whole displacement.
  EXPECT_LT(MaxAbsDiff(Se3Exp(0.5 * xi) * Se3Exp(0.5 * xi), cMcd), kExact);

  // The camera centre p(s) = translation of exp(s·ξ) is a helix about the screw axis
  // (direction ω̂, through q = ω × v / θ²): constant distance to the axis, advance along it
  // linear in s.
  const vpColVector v = Part(xi, 0), w = Part(xi, 3);
  const double theta = w.frobeniusNorm();
  const vpColVector w_hat = w / theta;
  const vpColVector q = vpColVector::crossProd(w, v) / (theta * theta);
  const double radius = q.frobeniusNorm();
  for (double s = 0.1; s <= 1.0001; s += 0.1) {
    const vpColVector p(Se3Exp(s * xi).getTranslationVector());
    const vpColVector r = p - q;
    const vpColVector across = r - vpColVector::dotProd(r, w_hat) * w_hat;
    EXPECT_NEAR(across.frobeniusNorm(), radius, kExact) << "s = " << s;
    EXPECT_NEAR(vpColVector::dotProd(p, w_hat), s * vpColVector::dotProd(v, w_hat), kExact)
        << "s = " << s;
  }

  // In closed loop with a perfect sensor, step k leaves exp((1 - Δ)^k ξ) to go: every pose on
  // the same geodesic.
  const vpHomogeneousMatrix cdMo(0.0, 0.0, 0.5, 0.0, 0.0, 0.0);
  vpHomogeneousMatrix cMo = cMcd * cdMo;
  ServoOptions options = Options(ServoMode::kExponential);
  options.delta = 0.8;
  double remaining = 1.0;
  for (int k = 0; k < 4; ++k) {
    const ServoStep step = ComputeServoStep(cMo, cdMo, options);
    ASSERT_EQ(step.status, ServoStatus::kRunning);
    EXPECT_LT(MaxAbsDiff(step.twist, 0.8 * remaining * xi), kExact) << "step " << k;
    cMo = step.c_T_cnew.inverse() * cMo;
    remaining *= 0.2;
  }
}

// ---- closed loop from random starts ---------------------------------------------------------

void ExpectAllConverge(ServoOptions options, int max_moves, double dt, int min_moves_expected,
                       int max_moves_expected) {
  std::mt19937 rng(42);
  const vpHomogeneousMatrix cdMo = RandomGoal();
  int worst = 0, best = max_moves;
  for (int trial = 0; trial < kTrials; ++trial) {
    const vpHomogeneousMatrix wMc = RandomStart_wMc(rng, cdMo);
    const RunResult r = RunLoop(wMc, vpHomogeneousMatrix(), cdMo, options, Perfect, max_moves, dt);
    ASSERT_TRUE(r.converged) << "trial " << trial << " after " << r.moves;
    EXPECT_LE(r.true_translation_error_m, kTolTranslationM) << "trial " << trial;
    EXPECT_LE(r.true_rotation_error_deg, kTolRotationDeg) << "trial " << trial;
    worst = std::max(worst, r.moves);
    best = std::min(best, r.moves);
  }
  std::cout << ToString(options.mode) << ": " << kTrials << " random starts, moves " << best << ".."
            << worst << "\n";
  EXPECT_GE(best, min_moves_expected);
  EXPECT_LE(worst, max_moves_expected);
}

TEST(PointAndGo, ConvergesFromRandomStartsInOneOrTwoMoves) {
  ExpectAllConverge(Options(ServoMode::kPointAndGo), 10, 0.0, 1, 2);
}

TEST(ExponentialLaw, ConvergesFromRandomStartsWithin10Moves) {
  ServoOptions options = Options(ServoMode::kExponential);
  options.delta = 0.8;
  ExpectAllConverge(options, 50, 0.0, 1, 10);
}

TEST(VelocityLaw, ConstantGainConvergesFromRandomStarts) {
  ServoOptions options = Options(ServoMode::kVelocity);
  options.gain = 2.0;  // 1/s, at dt = 0.05 s: e shrinks by ~10 % per period
  ExpectAllConverge(options, 1000, 0.05, 1, 120);
}

TEST(VelocityLaw, AdaptiveGainConvergesFromRandomStarts) {
  ServoOptions options = Options(ServoMode::kVelocity);
  options.adaptive_gain = true;
  options.gain_at_zero = 4.0;
  options.gain_at_infinity = 1.0;
  options.gain_slope_at_zero = 20.0;
  ExpectAllConverge(options, 1000, 0.05, 1, 120);
}

// ---- the paper's Table 3 --------------------------------------------------------------------

// Convention for Table 3's rows (X, Y, Z in mm, pitch, roll in degrees): the camera pose in the
// robot's base frame w (Z up). At pitch = roll = 0 the camera looks straight down: x_c = X_w,
// y_c = -Y_w, z_c = -Z_w, i.e. wRc = Rx(π)·Rx(pitch)·Rz(roll): pitch about the camera's x axis
// (positive tilts the optical axis towards +Y_w), roll about the optical axis. The target lies
// on the table (Z = 0) below the goal, its axes along the goal camera's.
vpHomogeneousMatrix Table3Pose(double x_mm, double y_mm, double z_mm, double pitch_deg,
                               double roll_deg) {
  const vpRotationMatrix R = vpRotationMatrix(vpThetaUVector(M_PI, 0, 0)) *
                             vpRotationMatrix(vpThetaUVector(vpMath::rad(pitch_deg), 0, 0)) *
                             vpRotationMatrix(vpThetaUVector(0, 0, vpMath::rad(roll_deg)));
  return vpHomogeneousMatrix(vpTranslationVector(x_mm * 1e-3, y_mm * 1e-3, z_mm * 1e-3), R);
}

struct Table3 {
  vpHomogeneousMatrix wMc_start = Table3Pose(490, 15, 610, -5, 0);
  vpHomogeneousMatrix wMcd = Table3Pose(550, -35, 550, 0, 0);
  vpHomogeneousMatrix wMo =
      vpHomogeneousMatrix(vpTranslationVector(0.550, -0.035, 0.0), wMcd.getRotationMatrix());
  vpHomogeneousMatrix cdMo = wMcd.inverse() * wMo;
};

TEST(Table3, ExponentialDelta08ConvergesWithin10Moves) {
  const Table3 t;
  ServoOptions options = Options(ServoMode::kExponential);
  options.delta = 0.8;
  std::cout << "Table 3, exponential, delta 0.8:\n";
  const RunResult r = RunLoop(t.wMc_start, t.wMo, t.cdMo, options, Perfect, 50, 0.0, true);
  ASSERT_TRUE(r.converged);
  EXPECT_LE(r.moves, 10);
  EXPECT_LE(r.true_translation_error_m, kTolTranslationM);
  EXPECT_LE(r.true_rotation_error_deg, kTolRotationDeg);
}

TEST(Table3, PointAndGoConvergesWithin3Moves) {
  const Table3 t;
  std::cout << "Table 3, point-and-go:\n";
  const RunResult r =
      RunLoop(t.wMc_start, t.wMo, t.cdMo, Options(ServoMode::kPointAndGo), Perfect, 50, 0.0, true);
  ASSERT_TRUE(r.converged);
  EXPECT_LE(r.moves, 3);
  EXPECT_LE(r.true_translation_error_m, kTolTranslationM);
  EXPECT_LE(r.true_rotation_error_deg, kTolRotationDeg);
}

// ---- perturbed pose estimates (the paper's argument for Eq. 6) ------------------------------

// A fixed estimation error: translation scaled by `scale`, and a fixed 1 deg rotation in the
// camera frame (as a small hand-eye or intrinsics error would give). The goal is taught with
// the same estimator, so the error vanishes at the goal.
Estimator Biased(double scale) {
  const vpHomogeneousMatrix bias(0, 0, 0, vpMath::rad(0.6), vpMath::rad(-0.8), 0.0);
  return [scale, bias](const vpHomogeneousMatrix& cMo) {
    vpHomogeneousMatrix out = bias * cMo;
    const vpTranslationVector t = out.getTranslationVector();
    out.insert(vpTranslationVector(scale * t[0], scale * t[1], scale * t[2]));
    return out;
  };
}

struct BiasedMoves {
  int point_and_go = 0, exponential = 0;
};

BiasedMoves RunBiased(const Estimator& estimate) {
  const Table3 t;
  ServoOptions exp_options = Options(ServoMode::kExponential);
  exp_options.delta = 0.8;
  const RunResult e = RunLoop(t.wMc_start, t.wMo, t.cdMo, exp_options, estimate, 50);
  const RunResult p =
      RunLoop(t.wMc_start, t.wMo, t.cdMo, Options(ServoMode::kPointAndGo), estimate, 50);
  EXPECT_TRUE(e.converged);
  EXPECT_TRUE(p.converged);
  EXPECT_LE(e.true_translation_error_m, kTolTranslationM);
  EXPECT_LE(e.true_rotation_error_deg, kTolRotationDeg);
  EXPECT_LE(p.true_translation_error_m, kTolTranslationM);
  EXPECT_LE(p.true_rotation_error_deg, kTolRotationDeg);
  return {p.moves, e.moves};
}

TEST(PerturbedEstimates, TwoPercentScaleBothConvergePointAndGoNeedsMoreMoves) {
  const BiasedMoves perfect = RunBiased(Perfect);
  const BiasedMoves biased = RunBiased(Biased(1.02));
  std::cout << "Table 3, perfect estimates: point-and-go " << perfect.point_and_go
            << " moves, exponential " << perfect.exponential
            << "; 2 % scale + 1 deg: " << biased.point_and_go << ", " << biased.exponential << "\n";
  EXPECT_GT(biased.point_and_go, perfect.point_and_go);
  EXPECT_LE(biased.exponential, 10);
}

TEST(PerturbedEstimates, OverestimatedDisplacementFavoursDeltaBelowOne) {
  // An estimator overestimating distances by 25 % (cf. the paper's uncorrected lens
  // distortion): point-and-go overshoots by 25 % of the remaining displacement each move,
  // Δ = 0.8 by |1 - 0.8·1.25| = 0.
  const BiasedMoves biased = RunBiased(Biased(1.25));
  std::cout << "Table 3, 25 % overestimate: point-and-go " << biased.point_and_go
            << " moves, exponential " << biased.exponential << "\n";
  EXPECT_LT(biased.exponential, biased.point_and_go);
}

// ---- options --------------------------------------------------------------------------------

TEST(ServoOptions, CheckNamesTheField) {
  ServoOptions options;
  EXPECT_NO_THROW(options.Check());
  options.delta = 1.5;
  try {
    options.Check();
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("delta"), std::string::npos) << e.what();
  }
  options = ServoOptions();
  options.rotation_tolerance_deg = 0.0;
  EXPECT_THROW(options.Check(), std::invalid_argument);
  EXPECT_THROW(ComputeServoStep(vpHomogeneousMatrix(), vpHomogeneousMatrix(), options),
               std::invalid_argument);
}

TEST(ServoMode, StringsRoundTrip) {
  for (ServoMode mode : {ServoMode::kPointAndGo, ServoMode::kExponential, ServoMode::kVelocity}) {
    EXPECT_EQ(ServoModeFromString(ToString(mode)), mode);
  }
  EXPECT_THROW(ServoModeFromString("pbvs"), std::invalid_argument);
  EXPECT_EQ(ToString(ServoStatus::kConverged), "converged");
}

TEST(ServoStep, ConvergedCommandsNoMotion) {
  const vpHomogeneousMatrix cdMo(0.0, 0.0, 0.5, 0.0, 0.0, 0.0);
  const vpHomogeneousMatrix cMo(0.0002, 0.0, 0.5, 0.0, 0.0, vpMath::rad(0.05));
  for (ServoMode mode : {ServoMode::kPointAndGo, ServoMode::kExponential, ServoMode::kVelocity}) {
    const ServoStep step = ComputeServoStep(cMo, cdMo, Options(mode));
    EXPECT_EQ(step.status, ServoStatus::kConverged) << ToString(mode);
    EXPECT_LT(MaxAbsDiff(step.c_T_cnew, vpHomogeneousMatrix()), kExact);
    EXPECT_LT(step.twist.frobeniusNorm(), kExact);
  }
}

}  // namespace
}  // namespace oal
