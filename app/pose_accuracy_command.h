#pragma once

namespace oal {

/// `oalservo pose-accuracy`: the pose's accuracy evaluation on rendered frames
/// (eval/rendered/pose_accuracy.h), printed as a table and optionally written as JSON.
int RunPoseAccuracy(int argc, char** argv);

}  // namespace oal
