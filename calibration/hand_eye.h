// The hand-eye transform eMc (the camera in the end-effector frame) from pairs of poses: where
// the robot says its end effector is (wMe) and where the camera sees the target (cMo), with
// the target fixed in the world.
//
// The solver is OpenCV's calibrateHandEye with Daniilidis' dual quaternions (rotation and
// translation together). ViSP 3.5's vpHandEyeCalibration solves as well (0.49 mm against 0.42
// mm mean error on 200 sets of 12 noisy pairs) but writes its own check of the result on the
// standard output, which no library of ours may do. Around it: the checks it does not make (enough
// pairs, rotations about more than one axis, no two pairs from one station) and the residuals
// a user can judge: through eMc every pair gives the target's pose in the world,
// wMo = wMe · eMc · cMo, and with a right eMc and exact poses they are all one.
#pragma once

#include <visp3/core/vpHomogeneousMatrix.h>

#include <string>
#include <vector>

namespace oal {

/// One station: the end effector in the world, read from the robot, and the target in the
/// camera, estimated in the frame taken there.
struct HandEyePair {
  vpHomogeneousMatrix wMe;
  vpHomogeneousMatrix cMo;
};

struct HandEyeOptions {
  int min_pairs = 4;  ///< Range [3, 10000]; ViSP needs 3, a check against noise one more.
  /// The arm must turn between stations about two axes at least this far apart, and by at
  /// least this much: with rotations about one axis only, the translation along it is free.
  /// Degrees, range [1, 90].
  double min_rotation_deg = 5.0;

  /// Throws std::invalid_argument naming the field, its value and the violated constraint.
  void Check() const;
};

/// How well one pair agrees with the result: its wMo = wMe · eMc · cMo against their mean.
struct HandEyePairResidual {
  double translation_mm = 0.0;
  double rotation_deg = 0.0;
};

struct HandEyeResult {
  vpHomogeneousMatrix eMc;
  vpHomogeneousMatrix wMo;                     ///< the target in the world: the mean over the pairs
  std::vector<HandEyePairResidual> residuals;  ///< one per pair, in order
  double rms_translation_mm = 0.0, rms_rotation_deg = 0.0;
  /// The widest angle between two rotation axes of the moves between stations, degrees: how
  /// well the stations pin eMc down (90 is best).
  double axis_spread_deg = 0.0;
  /// What the user can do about a weak result ("turn the arm more about ...").
  std::vector<std::string> advice;
};

/// Solves for eMc. Throws std::invalid_argument for options failing Check(), and
/// std::runtime_error saying why when the pairs cannot determine eMc: too few, the arm barely
/// turned or turned about one axis only, or the solver failed.
HandEyeResult CalibrateHandEye(const std::vector<HandEyePair>& pairs,
                               const HandEyeOptions& options = HandEyeOptions());

/// Where to take the views: end-effector poses around the current one.
struct HandEyeStationOptions {
  int count = 12;  ///< Range [4, 100].
  /// The camera turns about the target's centre, so the target stays in view: tilts of the
  /// optical axis up to this angle, degrees, range [2, 45] ...
  double tilt_deg = 15.0;
  /// ... and turns about the optical axis up to this angle, degrees, range [0, 90].
  double roll_deg = 20.0;

  void Check() const;
};

/// `count` end-effector poses wMe for the views, the camera turned about the point `cMo`'s
/// origin (the target seen now from the end effector at `wMe`) by alternating tilts in
/// directions spread around the optical axis and alternating rolls. `eMc_guess` is the mounting
/// as the user believes it: the stations are planned with it, and a guess off by centimetres
/// and degrees only moves the target in the image, it does not enter the result.
std::vector<vpHomogeneousMatrix> HandEyeStations(const vpHomogeneousMatrix& wMe,
                                                 const vpHomogeneousMatrix& eMc_guess,
                                                 const vpHomogeneousMatrix& cMo,
                                                 const HandEyeStationOptions& options);

}  // namespace oal
