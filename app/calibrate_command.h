#pragma once

namespace oal {

/// `oalservo calibrate INPUT... --chessboard COLSxROWS --square M --out camera.xml`: the
/// camera's intrinsics and ViSP's distortion from views of a printed chessboard
/// (calibration/), written as a ViSP camera file.
int RunCalibrate(int argc, char** argv);

}  // namespace oal
