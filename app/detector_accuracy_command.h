#pragma once

namespace oal {

/// `oalservo detect-accuracy`: the detector's accuracy evaluation on rendered frames
/// (eval/rendered/detector_accuracy.h), printed as a table and optionally written as JSON.
int RunDetectAccuracy(int argc, char** argv);

}  // namespace oal
