// How far apart two poses are: the one measure of every pose error, pose jump and step size.
// The only header of base/ that uses ViSP (its pose types, header-only): include it from a
// library that links ViSP core.
#pragma once

#include <visp3/core/vpHomogeneousMatrix.h>
#include <visp3/core/vpThetaUVector.h>

namespace oal {

/// Distance between two poses: translation in metres and rotation angle in radians of
/// a^-1 * b. For two poses of one thing in one frame (two cMo, two wMc) the translation is
/// |t_a - t_b| and the angle that of R_a R_b^T.
struct PoseDistance {
  double translation_m = 0;
  double rotation_rad = 0;
};

inline PoseDistance Distance(const vpHomogeneousMatrix& a, const vpHomogeneousMatrix& b) {
  const vpHomogeneousMatrix aMb = a.inverse() * b;
  PoseDistance d;
  d.translation_m = aMb.getTranslationVector().frobeniusNorm();
  d.rotation_rad = vpThetaUVector(aMb.getRotationMatrix()).getTheta();
  return d;
}

}  // namespace oal
