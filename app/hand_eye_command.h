// `oalservo hand-eye`: the hand-eye transform eMc (calibration/hand_eye.h), either by moving
// the configured arm through stations around where it stands and taking a pair at each
// (--config, calibration/hand_eye_routine.h), or from pairs recorded before (--pairs CSV).
// Writes a configuration file holding camera.eMc, to give after the robot's own:
//   oalservo servo --config robot.yaml --config hand-eye.yaml
//
// The pairs CSV: a header, then one row per station, poses as the configuration writes them
// (metres; x-y-z Euler angles in degrees, R = Rx·Ry·Rz):
//   wMe_x_m,wMe_y_m,wMe_z_m,wMe_rx_deg,wMe_ry_deg,wMe_rz_deg,cMo_x_m,...,cMo_rz_deg
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "calibration/hand_eye.h"

namespace oal {

/// The pairs in a CSV at `path` (the form above). Throws std::runtime_error "FILE:LINE: ..."
/// naming the column for a malformed row.
std::vector<HandEyePair> ReadHandEyePairs(const std::string& path);
/// The pairs as CSV, the header first.
void WriteHandEyePairs(const std::vector<HandEyePair>& pairs, std::ostream& out);

int RunHandEye(int argc, char** argv);

}  // namespace oal
