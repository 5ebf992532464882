// How far apart two poses are: the one measure of every pose error, pose jump and step size.
// The only header of base/ that uses ViSP (its pose types, header-only): include it from a
// library that links ViSP core.
#pragma once

#include <visp3/core/vpHomogeneousMatrix.h>

#include <cmath>

namespace oal {

/// Distance between two poses: translation in metres and rotation angle in radians of
/// a^-1 * b. For two poses of one thing in one frame (two cMo, two wMc) the translation is
/// |t_a - t_b| and the angle that of R_a R_b^T.
struct PoseDistance {
  double translation_m = 0;
  double rotation_rad = 0;
};

inline PoseDistance Distance(const vpHomogeneousMatrix& a, const vpHomogeneousMatrix& b) {
  // Element by element: ViSP's products and inverse allocate, and a tracker measures a jump
  // every frame. |a^-1 b|'s translation is |t_b - t_a|; its rotation R_a^T R_b turns by the
  // angle whose cosine is (trace - 1) / 2 and sine half the norm of its skew part (atan2 of
  // the two: exact near 0 and near 180 degrees, as vpThetaUVector).
  double m[3][3];
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      m[i][j] = a[0][i] * b[0][j] + a[1][i] * b[1][j] + a[2][i] * b[2][j];
    }
  }
  const double du = b[0][3] - a[0][3], dv = b[1][3] - a[1][3], dw = b[2][3] - a[2][3];
  const double sx = m[2][1] - m[1][2], sy = m[0][2] - m[2][0], sz = m[1][0] - m[0][1];
  PoseDistance d;
  d.translation_m = std::sqrt(du * du + dv * dv + dw * dw);
  d.rotation_rad = std::atan2(0.5 * std::sqrt(sx * sx + sy * sy + sz * sz),
                              0.5 * (m[0][0] + m[1][1] + m[2][2] - 1.0));
  return d;
}

}  // namespace oal
