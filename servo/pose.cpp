// Steps 2-4 of the pose (pose.h): corners -> vpPose (Dementhon, Lagrange, virtual visual
// servoing), roll, pitch, yaw and the paper's plane angles.
#include "servo/pose.h"

#include <visp3/core/vpException.h>
#include <visp3/core/vpPoint.h>
#include <visp3/core/vpRzyxVector.h>
#include <visp3/vision/vpPose.h>

#include <Eigen/Dense>
#include <cmath>
#include <exception>
#include <limits>
#include <sstream>
#include <utility>

#include "base/angles.h"
#include "detector/lens.h"
#include "servo/pose_internal.h"
#include "servo/target_layout.h"

namespace oal {
namespace {

using pose_internal::HashTarget;

double Wrap360(double deg) {
  double wrapped = std::fmod(deg, 360.0);
  if (wrapped < 0.0) wrapped += 360.0;
  return wrapped >= 360.0 ? 0.0 : wrapped;
}

double Wrap180(double deg) {
  const double wrapped = Wrap360(deg + 180.0) - 180.0;
  return wrapped <= -180.0 ? wrapped + 360.0 : wrapped;
}

// Reprojection RMS of the corners in undistorted pixels, +inf if a corner is not in front.
double ResidualPx(const vpHomogeneousMatrix& cMo, const HashTarget& target,
                  const std::array<vpColVector, 4>& corners_m, const Lens& camera) {
  double sum = 0.0;
  for (int k = 0; k < 4; ++k) {
    const double ox = target.corner[k].x, oy = target.corner[k].y;
    const double xc = cMo[0][0] * ox + cMo[0][1] * oy + cMo[0][3];
    const double yc = cMo[1][0] * ox + cMo[1][1] * oy + cMo[1][3];
    const double zc = cMo[2][0] * ox + cMo[2][1] * oy + cMo[2][3];
    if (!(zc > 0.0)) return std::numeric_limits<double>::infinity();
    const double du = camera.px() * (xc / zc - corners_m[k][0]);
    const double dv = camera.py() * (yc / zc - corners_m[k][1]);
    sum += du * du + dv * dv;
  }
  const double rms = std::sqrt(sum / 4.0);
  return std::isfinite(rms) ? rms : std::numeric_limits<double>::infinity();
}

bool IsFinite(const vpHomogeneousMatrix& m) {
  for (unsigned r = 0; r < 3; ++r)
    for (unsigned c = 0; c < 4; ++c)
      if (!std::isfinite(m[r][c])) return false;
  return true;
}

// Runs one vpPose method from `*cMo` (the seed for VIRTUAL_VS); false on any failure.
bool Compute(vpPose* pose, vpPose::vpPoseMethodType method, vpHomogeneousMatrix* cMo) {
  try {
    return pose->computePose(method, *cMo) && IsFinite(*cMo);
  } catch (const vpException&) {
    return false;
  } catch (const std::exception&) {
    return false;
  }
}

// Undistorted pixel of a board point seen from cMo (false when not in front of the camera).
bool Project(const vpHomogeneousMatrix& cMo, const Lens& camera, double x, double y, Point2d* out) {
  const double xc = cMo[0][0] * x + cMo[0][1] * y + cMo[0][3];
  const double yc = cMo[1][0] * x + cMo[1][1] * y + cMo[1][3];
  const double zc = cMo[2][0] * x + cMo[2][1] * y + cMo[2][3];
  if (!(zc > 0.0)) return false;
  out->u = camera.u0() + camera.px() * xc / zc;
  out->v = camera.v0() + camera.py() * yc / zc;
  return true;
}

// The bisector of two nearly parallel lines: the middle of a stripe between its edges.
LineParams Middle(const LineParams& a, const LineParams& b) {
  double ca = std::cos(a.theta_rad), sa = std::sin(a.theta_rad), ra = a.rho_px;
  double cb = std::cos(b.theta_rad), sb = std::sin(b.theta_rad), rb = b.rho_px;
  if (ca * cb + sa * sb < 0.0) {
    cb = -cb;
    sb = -sb;
    rb = -rb;
  }
  const double nu = ca + cb, nv = sa + sb, norm = std::hypot(nu, nv);
  return Normalized((ra + rb) / norm, std::atan2(nv / norm, nu / norm));
}

// How far each corner's image lies from where the detector's stripe middles put it, seen from
// cMo: corner image (centre lines) minus intersection of the stripe middles (pose.h,
// correct_stripe_centres). False if some image cannot be formed.
bool StripeCentreShifts(const vpHomogeneousMatrix& cMo, const HashTarget& target,
                        const Lens& camera, const std::array<bool, 4>& is_stripe,
                        std::array<Point2d, 4>* shift) {
  std::array<LineParams, 4> centre, seen;
  for (int k = 0; k < 4; ++k) {
    const auto& a = target.corner[(k + 3) % 4];  // the two corners on line k
    const auto& b = target.corner[k];
    Point2d pa, pb;
    if (!Project(cMo, camera, a.x, a.y, &pa) || !Project(cMo, camera, b.x, b.y, &pb)) return false;
    centre[k] = LineThrough(pa, pb);
    seen[k] = centre[k];
    if (!is_stripe[k]) continue;
    const double hx = 0.5 * target.width_m[k] * target.normal[k].x;
    const double hy = 0.5 * target.width_m[k] * target.normal[k].y;
    Point2d ea, eb, fa, fb;
    if (!Project(cMo, camera, a.x + hx, a.y + hy, &ea) ||
        !Project(cMo, camera, b.x + hx, b.y + hy, &eb) ||
        !Project(cMo, camera, a.x - hx, a.y - hy, &fa) ||
        !Project(cMo, camera, b.x - hx, b.y - hy, &fb)) {
      return false;
    }
    seen[k] = Middle(LineThrough(ea, eb), LineThrough(fa, fb));
  }
  for (int k = 0; k < 4; ++k) {
    Point2d c, m;
    if (!Intersect(centre[k], centre[(k + 1) % 4], &c, 1e-6) ||
        !Intersect(seen[k], seen[(k + 1) % 4], &m, 1e-6)) {
      return false;
    }
    (*shift)[k] = Point2d{c.u - m.u, c.v - m.v};
  }
  return true;
}

// The four corners handed to vpPose: the measured intersections, moved by the stripe-centre
// shifts seen from a pose when there is one (pose.h, correct_stripe_centres).
struct Corners {
  const std::array<Point2d, 4>& measured_px;
  const std::array<bool, 4>& is_stripe;
  const HashTarget& hash;
  const PoseOptions& options;

  // `pose` may be null: the corners only (the previous-pose path refines without vpPose).
  void Set(const vpHomogeneousMatrix* seen_from, PoseResult* result, vpPose* pose) const {
    const bool any_stripe = is_stripe[0] || is_stripe[1] || is_stripe[2] || is_stripe[3];
    std::array<Point2d, 4> shift{};
    if (seen_from == nullptr || !options.correct_stripe_centres || !any_stripe ||
        !StripeCentreShifts(*seen_from, hash, options.camera, is_stripe, &shift)) {
      shift = {};
    }
    if (pose != nullptr) pose->clearPoint();
    for (int k = 0; k < 4; ++k) {
      result->corners_px[k] = Point2d{measured_px[k].u + shift[k].u, measured_px[k].v + shift[k].v};
      double x = 0.0, y = 0.0;
      pose_internal::PixelToMetre(options.camera, options.lines_undistorted, result->corners_px[k],
                                  &x, &y);
      result->corners_m[k].resize(2, false);
      result->corners_m[k][0] = x;
      result->corners_m[k][1] = y;
      if (pose == nullptr) continue;
      vpPoint point(hash.corner[k].x, hash.corner[k].y, 0.0);
      point.set_x(x);
      point.set_y(y);
      pose->addPoint(point);
    }
  }
};

// The rotation and translation of vpExponentialMap::direct(v) (v = [translation; theta-u],
// over a unit time), on fixed-size matrices: it allocates nothing.
void TwistExp(const Eigen::Matrix<double, 6, 1>& v, Eigen::Matrix3d* rotation,
              Eigen::Vector3d* translation) {
  const Eigen::Vector3d u = v.tail<3>();
  const double theta = u.norm();
  Eigen::Matrix3d skew;
  skew << 0.0, -u.z(), u.y(), u.z(), 0.0, -u.x(), -u.y(), u.x(), 0.0;
  // sin(t)/t, (1 - cos(t))/t², (1 - sin(t)/t)/t², by their series near 0.
  double sinc = 1.0, mcosc = 0.5, msinc = 1.0 / 6.0;
  if (theta > 1e-6) {
    const double t2 = theta * theta;
    sinc = std::sin(theta) / theta;
    mcosc = (1.0 - std::cos(theta)) / t2;
    msinc = (1.0 - sinc) / t2;
  }
  *rotation = Eigen::Matrix3d::Identity() + sinc * skew + mcosc * skew * skew;
  const Eigen::Matrix3d V =
      sinc * Eigen::Matrix3d::Identity() + mcosc * skew + msinc * u * u.transpose();
  *translation = V * v.head<3>();
}

// Gauss-Newton refinement of cMo on the four corners, the model of vpPose::VIRTUAL_VS (same
// reprojection error in normalised coordinates, same camera-frame update
// cMo <- exp(v)^-1 · cMo), on fixed-size matrices: the previous-pose path runs it on every
// frame of a loop, where vpPose's (and ViSP's matrices') allocations cost more than the
// arithmetic. False when a corner falls behind the camera or the normal equations are
// singular.
bool RefineOnCorners(const HashTarget& hash, const std::array<vpColVector, 4>& corners_m,
                     vpHomogeneousMatrix* cMo) {
  constexpr int kMaxIterations = 20;
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) R(r, c) = (*cMo)[r][c];
    t(r) = (*cMo)[r][3];
  }
  double measured[4][2];
  for (int k = 0; k < 4; ++k) {
    measured[k][0] = corners_m[k][0];
    measured[k][1] = corners_m[k][1];
  }
  for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
    Eigen::Matrix<double, 8, 6> L;
    Eigen::Matrix<double, 8, 1> e;
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d p =
          R.col(0) * hash.corner[k].x + R.col(1) * hash.corner[k].y + t;  // object z = 0
      if (!(p.z() > 0.0)) return false;
      const double iz = 1.0 / p.z(), x = p.x() * iz, y = p.y() * iz;
      e(2 * k) = x - measured[k][0];
      e(2 * k + 1) = y - measured[k][1];
      L.row(2 * k) << -iz, 0.0, x * iz, x * y, -(1.0 + x * x), y;
      L.row(2 * k + 1) << 0.0, -iz, y * iz, 1.0 + y * y, -x * y, -x;
    }
    const Eigen::Matrix<double, 6, 6> normal = L.transpose() * L;
    const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> solver(normal);
    if (solver.info() != Eigen::Success) return false;
    const Eigen::Matrix<double, 6, 1> v = -solver.solve(L.transpose() * e);
    if (!v.allFinite()) return false;
    Eigen::Matrix3d step_rotation;
    Eigen::Vector3d step_translation;
    TwistExp(v, &step_rotation, &step_translation);
    // exp(v)^-1 · cMo
    R = step_rotation.transpose() * R;
    t = step_rotation.transpose() * (t - step_translation);
    if (v.norm() < 1e-12) break;
  }
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) (*cMo)[r][c] = R(r, c);
    (*cMo)[r][3] = t(r);
  }
  return IsFinite(*cMo);
}

// Step 4's refinement from `*cMo`: RefineOnCorners, or vpPose's virtual visual servoing on
// the same corners (`pose` holds them) where it fails.
bool Refine(const HashTarget& hash, const std::array<vpColVector, 4>& corners_m, vpPose* pose,
            vpHomogeneousMatrix* cMo) {
  vpHomogeneousMatrix refined = *cMo;
  if (RefineOnCorners(hash, corners_m, &refined)) {
    *cMo = refined;
    return true;
  }
  return Compute(pose, vpPose::VIRTUAL_VS, cMo);
}

PoseResult Fail(PoseResult result, const std::string& message) {
  result.status = PoseStatus::kDegenerate;
  result.message = message;
  result.cMo.eye();
  return result;
}

// A pose seeded from elsewhere, refined on the corners (seen from the seed for the stripe-centre
// shifts), is kept alone when it fits within `accept_px`, and the linear methods are skipped:
// in a loop the previous pose, on a first frame the pose of the corners' homography. Whether
// it was kept.
bool KeepSeededPose(const vpHomogeneousMatrix& seed, PoseMethod method, double accept_px,
                    const Corners& corners, const HashTarget& hash, const PoseOptions& options,
                    PoseResult* result, vpHomogeneousMatrix* cMo, double* residual_px) {
  vpHomogeneousMatrix seeded = seed;
  corners.Set(&seeded, result, nullptr);
  if (!RefineOnCorners(hash, result->corners_m, &seeded)) return false;
  const double seeded_px = ResidualPx(seeded, hash, result->corners_m, options.camera);
  if (!(seeded_px < accept_px)) return false;
  *cMo = seeded;
  *residual_px = seeded_px;
  result->method = method;
  result->from_previous = method == PoseMethod::kPrevious;
  return true;
}

// The plane pose whose homography H ~ [r1 r2 t] takes the target's four corners (board plane,
// metres) onto the measured ones (normalised): four points fix it exactly, so it is as good a
// start as vpPose's linear methods on the same four, at a fraction of their cost. Nullopt when
// the corners are degenerate.
std::optional<vpHomogeneousMatrix> HomographyPose(const HashTarget& hash,
                                                  const std::array<vpColVector, 4>& corners_m) {
  std::array<Point2d, 4> plane, image;
  Point2d centre{0.0, 0.0};
  for (int k = 0; k < 4; ++k) {
    plane[k] = Point2d{hash.corner[k].x, hash.corner[k].y};
    image[k] = Point2d{corners_m[k][0], corners_m[k][1]};
    centre = Point2d{centre.u + 0.25 * plane[k].u, centre.v + 0.25 * plane[k].v};
  }
  const std::optional<vpHomography> found = FourPointHomography(plane, image, centre);
  if (!found) return std::nullopt;
  return PlanePose(*found);  // positive third coordinate inside: the plane in front
}

// Steps 3-4: Lagrange, and Dementhon unless Lagrange's residual is already below
// dementhon_above_px (where the refinement would end in the same minimum anyway); the lower
// residual is refined by virtual visual servoing, and so is the previous pose when there is one
// (kept when its residual is within previous_tolerance_px). Why no pose was found, if none.
std::optional<std::string> LinearPoseRefined(const vpHomogeneousMatrix* previous_cMo,
                                             const Corners& corners, const HashTarget& hash,
                                             const PoseOptions& options, vpPose* pose,
                                             PoseResult* result, vpHomogeneousMatrix* cMo,
                                             double* residual_px) {
  const Lens& camera = options.camera;
  corners.Set(nullptr, result, pose);
  vpHomogeneousMatrix by_dementhon, by_lagrange;
  const bool lagrange_ok = Compute(pose, vpPose::LAGRANGE, &by_lagrange);
  const double lagrange_px =
      lagrange_ok ? ResidualPx(by_lagrange, hash, result->corners_m, camera) : HUGE_VAL;
  const bool run_dementhon = !(lagrange_px < options.dementhon_above_px);
  const bool dementhon_ok = run_dementhon && Compute(pose, vpPose::DEMENTHON, &by_dementhon);
  const double dementhon_px =
      dementhon_ok ? ResidualPx(by_dementhon, hash, result->corners_m, camera) : HUGE_VAL;
  if (!std::isfinite(dementhon_px) && !std::isfinite(lagrange_px)) {
    return "vpPose found no pose in front of the camera (Dementhon and Lagrange failed)";
  }
  result->method = dementhon_px <= lagrange_px ? PoseMethod::kDementhon : PoseMethod::kLagrange;
  *cMo = result->method == PoseMethod::kDementhon ? by_dementhon : by_lagrange;
  // The stripe-centre shifts are a small fraction of a pixel and change little with the
  // pose: seen from the linear pose, one refinement after them suffices.
  const vpHomogeneousMatrix linear = *cMo;
  corners.Set(&linear, result, pose);
  if (Refine(hash, result->corners_m, pose, cMo)) {
    *residual_px = ResidualPx(*cMo, hash, result->corners_m, camera);
  }
  if (previous_cMo != nullptr) {
    vpHomogeneousMatrix seeded = *previous_cMo;
    if (Refine(hash, result->corners_m, pose, &seeded)) {
      const double seeded_px = ResidualPx(seeded, hash, result->corners_m, camera);
      if (std::isfinite(seeded_px) && seeded_px <= *residual_px + options.previous_tolerance_px) {
        *cMo = seeded;
        *residual_px = seeded_px;
        result->from_previous = true;
      }
    }
  }
  return std::nullopt;
}

// Step 2: the roll of line 1, from its corner with line 2 (corner 0) to its corner with line 4
// (corner 3), in (undistorted) pixels, after the stripe-centre correction.
double Line1RollDeg(const PoseResult& result, const Lens& camera) {
  const double du = camera.px() * (result.corners_m[3][0] - result.corners_m[0][0]);
  const double dv = camera.py() * (result.corners_m[3][1] - result.corners_m[0][1]);
  return Wrap360(std::atan2(-du, dv) * kDegPerRad);
}

// Why the pose cannot be right, if it cannot: a corner behind the camera, the board seen from
// behind, or a residual above max_residual_px.
std::optional<std::string> Implausible(const vpHomogeneousMatrix& cMo, double residual_px,
                                       const HashTarget& hash, const PoseOptions& options) {
  for (int k = 0; k < 4; ++k) {
    const double zc = cMo[2][0] * hash.corner[k].x + cMo[2][1] * hash.corner[k].y + cMo[2][3];
    if (!(zc >= options.min_depth_m)) {
      std::ostringstream message;
      message << "pose behind the camera: corner " << k + 1 << " at depth " << zc
              << " m (min_depth_m = " << options.min_depth_m << ")";
      return message.str();
    }
  }
  // The camera's object z, the third row of oMc = cMo^-1's translation -cRo^T cto.
  const double camera_z = -(cMo[0][2] * cMo[0][3] + cMo[1][2] * cMo[1][3] + cMo[2][2] * cMo[2][3]);
  if (!(camera_z < 0.0)) return "pose sees the back of the board (camera at object z >= 0)";
  if (residual_px > options.max_residual_px) {
    std::ostringstream message;
    message << "reprojection residual " << residual_px
            << " px > max_residual_px = " << options.max_residual_px;
    return message.str();
  }
  return std::nullopt;
}

// Roll, yaw and pitch of cMo, and Eq. 5: the board normal (object z in the camera frame)
// against lines 1 and 2.
void SetAngles(const vpHomogeneousMatrix& cMo, const HashTarget& hash, PoseResult* result) {
  const vpRotationMatrix cRo = cMo.getRotationMatrix();
  const vpRzyxVector rzyx(cRo);
  result->roll_deg = Wrap360(rzyx[0] * kDegPerRad);
  result->yaw_deg = Wrap180(rzyx[1] * kDegPerRad);
  result->pitch_deg = Wrap180(rzyx[2] * kDegPerRad);
  const double n[3] = {cRo[0][2], cRo[1][2], cRo[2][2]};
  for (int k = 0; k < 2; ++k) {
    const double dx = cRo[0][0] * hash.direction[k].x + cRo[0][1] * hash.direction[k].y;
    const double dy = cRo[1][0] * hash.direction[k].x + cRo[1][1] * hash.direction[k].y;
    const double norm = std::hypot(dx, dy);
    // m = z × d, the in-image direction across the line.
    const double across = norm > 0.0 ? (n[0] * -dy + n[1] * dx) / norm : 0.0;
    result->plane_angle_deg[k] = std::atan2(-across, n[2]) * kDegPerRad;
  }
}

}  // namespace

void ReplacePose(const vpHomogeneousMatrix& cMo, const LineTarget& target, PoseResult* result) {
  result->cMo = cMo;
  SetAngles(cMo, pose_internal::HashTargetFrom(target), result);
}

PoseResult EstimatePose(const std::vector<DetectedLine>& lines, const LineTarget& target,
                        const PoseOptions& options,
                        const std::optional<vpHomogeneousMatrix>& previous_cMo) {
  options.Check();
  const HashTarget hash = pose_internal::HashTargetFrom(target);
  // Step 1.
  const bool have_previous = previous_cMo && IsFinite(*previous_cMo);
  const vpRotationMatrix previous_cRo =
      have_previous ? previous_cMo->getRotationMatrix() : vpRotationMatrix();
  PoseResult result =
      pose_internal::Identify(lines, hash, options, have_previous ? &previous_cRo : nullptr);
  if (result.status != PoseStatus::kOk) return result;

  std::array<bool, 4> is_stripe{};
  for (int k = 0; k < 4; ++k) is_stripe[k] = lines[result.line_index[k]].width_px > 0.0;
  // Corners::Set rewrites result.corners_px from the measured ones: a copy, not a reference.
  const std::array<Point2d, 4> measured_px = result.corners_px;
  const Corners corners{measured_px, is_stripe, hash, options};
  vpPose pose;
  pose.setVvsIterMax(options.vvs_max_iterations);
  vpHomogeneousMatrix cMo;
  double residual_px = HUGE_VAL;
  // The pose the refinement starts from when it is kept alone: the previous one, or the
  // corners' homography's.
  std::optional<vpHomogeneousMatrix> seed;
  bool kept_seed = false;
  if (have_previous && options.previous_accept_px > 0.0) {
    seed = *previous_cMo;
    kept_seed = KeepSeededPose(*seed, PoseMethod::kPrevious, options.previous_accept_px, corners,
                               hash, options, &result, &cMo, &residual_px);
  } else if (!have_previous && options.homography_accept_px > 0.0) {
    corners.Set(nullptr, &result, nullptr);
    seed = HomographyPose(hash, result.corners_m);
    kept_seed = seed && KeepSeededPose(*seed, PoseMethod::kHomography, options.homography_accept_px,
                                       corners, hash, options, &result, &cMo, &residual_px);
  }
  if (!kept_seed) {
    if (const std::optional<std::string> failure =
            LinearPoseRefined(have_previous ? &*previous_cMo : nullptr, corners, hash, options,
                              &pose, &result, &cMo, &residual_px)) {
      return Fail(std::move(result), *failure);
    }
  }
  result.line1_roll_deg = Line1RollDeg(result, options.camera);
  vpMatrix covariance;
  if (options.compute_covariance && std::isfinite(residual_px)) {
    // A kept seed was refined without vpPose: give it the same corners.
    if (kept_seed) corners.Set(&*seed, &result, &pose);
    // From the converged pose the refinement stops after an iteration or two.
    pose.setCovarianceComputation(true);
    vpHomogeneousMatrix refined = cMo;
    if (Compute(&pose, vpPose::VIRTUAL_VS, &refined)) covariance = pose.getCovarianceMatrix();
  }
  if (!std::isfinite(residual_px)) {
    return Fail(std::move(result), "vpPose's virtual visual servoing did not converge");
  }
  result.residual_px = residual_px;
  if (const std::optional<std::string> why = Implausible(cMo, residual_px, hash, options)) {
    return Fail(std::move(result), *why);
  }
  result.cMo = cMo;
  result.covariance = covariance;
  SetAngles(cMo, hash, &result);
  result.status = PoseStatus::kOk;
  result.message.clear();
  return result;
}

}  // namespace oal
