#pragma once

namespace oal {

/// `oalservo calibrate-accuracy`: calibration from the printed line target on rendered views of
/// known cameras (eval/rendered/calibrate_accuracy.h), printed as a table and optionally written as
/// JSON.
int RunCalibrateAccuracy(int argc, char** argv);

}  // namespace oal
