// A ChArUco board printed on the sheet instead of our target, found and posed by OpenCV's
// aruco module (OpenCV 4.6's API), as a user of OpenCV would (eval/rendered/marker_method.h).
//
// The print: CharucoBoard::create(10, 7, square, 0.75 square, DICT_5X5_100) drawn by
// board->draw at 60 pixels a square (the chessboard's squares exact; the markers where OpenCV
// puts them), centred on the sheet: 0.038 m squares on A3 (0.380 x 0.266 m), in proportion on
// a smaller sheet (A4 0.0269 m), the white paper around it.
//
// The pose, as OpenCV's ChArUco sample (detect_board_charuco) does it with its refinement on:
// detectMarkers (default parameters), refineDetectedMarkers (the markers the board's layout
// says were missed: 197 frames with a pose of 200 instead of 179 on the tidy A3 bench),
// interpolateCornersCharuco with the camera (pose-based interpolation, then cornerSubPix; 2
// adjacent markers a corner) and estimatePoseCharucoBoard (at least 4 corners, solvePnP), the
// board's frame moved to the sheet's centre.
//
// The lens. OpenCV's camera matrix from px, py, u0, v0, and its distortion coefficients
// (k1, k2, 0, 0, k3) fitted to a kdu lens over the image (OpenCvDistortion), a lens in OpenCV's
// model as it is: the
// renderer forms the image with ViSP's kdu model exactly (distorted pixel -> ray), which our
// tracker and ViSP's AprilTag pose use as it is. ViSP's kud alone is exactly OpenCV's k1
// (KudAsOpenCvDistortion: u = u0 + px x (1 + kud r^2), r^2 = x^2 + y^2 of the undistorted
// point), but kud is only kdu's least-squares inverse (detector/lens.h FitKud): with kdu 0.15 it
// misses the rendered lens by up to 1.7 px at 640 x 480 and 8.6 px at 1920 x 1080, where the
// three coefficients stay under 0.01 and 0.1 px: what calibrating this camera with OpenCV's
// default model would give. With kud alone the board's poses are off by 0.11 % of the distance
// (median, 640 x 480) and 0.19 % (1280 x 720) instead of 0.027 % and 0.029 %.
//
// The pixels. The aruco module gives its corners in pixels whose centres lie at
// (i + 1/2, j + 1/2), half a pixel right of and below ours and the rest of OpenCV's
// (cornerSubPix, a camera matrix from calibrateCamera); taken with the camera matrix as it is,
// the poses are off by 0.12 % of the distance (median) instead of 0.027 %. The camera matrix it
// is handed has its principal point moved by that half pixel (InArucoPixels in the .cpp),
// which poses the corners where they are.
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "detector/lens.h"
#include "eval/rendered/marker_method.h"

namespace oal {

/// The ChArUco squares' side on `sheet`'s board, metres: 0.038 m scaled by the smaller of the
/// sheet's width / 0.42 m and height / 0.297 m (A3's).
double CharucoSquareSide(const LineTarget& sheet);

/// OpenCV's camera matrix (3 x 3) of a ViSP camera.
cv::Matx33d OpenCvCameraMatrix(const Lens& camera);
/// ViSP's metre -> pixel direction (kud) as OpenCV's distortion coefficients: (kud, 0, 0, 0,
/// 0), exactly; none for a camera without distortion.
cv::Matx<double, 1, 5> KudAsOpenCvDistortion(const Lens& camera);
/// The lens as OpenCV's distortion coefficients (5, or 8 for the rational model): its own in
/// OpenCV's model; for ViSP's kdu lens (pixel -> metre) the (k1, k2, 0, 0, k3) that best
/// follow it over the width x height image (Lens::OpenCvCamera); zeros without distortion.
std::vector<double> OpenCvDistortion(const Lens& camera, int width, int height);

std::unique_ptr<MarkerMethod> MakeCharucoMethod(const LineTarget& sheet, const Lens& camera,
                                                int width, int height);

}  // namespace oal
