// `oalservo camera`: a camera file read and shown (its lens model, intrinsics and
// coefficients), and written again in another format (ViSP's XML, OpenCV's calibration YAML,
// ROS's camera_info), saying when the new format can hold only an approximation.
#pragma once

namespace oal {

/// `oalservo camera FILE [--out OUT [--ros]]`; argv[0] is "camera".
int RunCamera(int argc, char** argv);

}  // namespace oal
