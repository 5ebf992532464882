// Small 3-D helpers shared by the renderer and the sequences (internal to scene/).
#pragma once

#include <visp3/core/vpHomogeneousMatrix.h>

#include <cmath>

namespace oal::scene_geometry {

struct Vec3 {
  double x = 0.0, y = 0.0, z = 0.0;
};

inline Vec3 Cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

inline Vec3 Unit(const Vec3& a) {
  const double n = std::sqrt(a.x * a.x + a.y * a.y + a.z * a.z);
  return {a.x / n, a.y / n, a.z / n};
}

/// a·u + b·v.
inline Vec3 Combine(double a, const Vec3& u, double b, const Vec3& v) {
  return {a * u.x + b * v.x, a * u.y + b * v.y, a * u.z + b * v.z};
}

/// cMo of a camera whose axes x, y, z (unit, object frame) are the rows of cRo and whose
/// centre is `centre` (object frame): cto = -cRo · centre.
inline vpHomogeneousMatrix PoseFromCameraAxes(const Vec3& x, const Vec3& y, const Vec3& z,
                                              const Vec3& centre) {
  vpHomogeneousMatrix cMo;
  const Vec3 axes[3] = {x, y, z};
  for (int r = 0; r < 3; ++r) {
    cMo[r][0] = axes[r].x;
    cMo[r][1] = axes[r].y;
    cMo[r][2] = axes[r].z;
    cMo[r][3] = -(axes[r].x * centre.x + axes[r].y * centre.y + axes[r].z * centre.z);
  }
  return cMo;
}

}  // namespace oal::scene_geometry
