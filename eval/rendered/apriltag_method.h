// An AprilTag 36h11 printed on the sheet instead of our target, found and posed by ViSP's
// vpDetectorAprilTag, as a user of ViSP would (eval/rendered/marker_method.h).
//
// The print: OpenCV's cv::aruco::drawMarker of DICT_APRILTAG_36h11, id 0 (the tag's 8 x 8
// modules: its black border and 6 x 6 data bits), centred on the sheet in a white border of
// 3/4 of a module that reaches the sheet's short side: the largest tag that fits with a white
// border (black square 0.250 m on A3, 0.177 m on A4).
//
// The lens. ViSP 3.5's getPose with its default estimator, HOMOGRAPHY_VIRTUAL_VS, does take
// the camera's distortion into account: a homography from the four corners (through a pinhole,
// the lens ignored), then ViSP's virtual visual servoing on the corners converted to metres
// with vpPixelMeterConversion, i.e. undistorted with the camera's kdu (its HOMOGRAPHY and
// HOMOGRAPHY_ORTHOGONAL_ITERATION stop before that and ignore the lens). But the corners are
// the AprilTag library's, where the straight lines it fits to the tag's four edges meet, and in
// a distorted frame those edges are curves: at kdu 0.15 the corners are off by enough to bias
// the pose by 0.33 % of the distance (median; 0.010 % with the same frames undistorted). Our
// tracker undistorts its edge points before fitting its lines; the tag gets the same: each
// frame is resampled as the ideal pinhole camera would see it (the lens's kdu exactly, the
// canvas covering the whole frame; the time it takes counted in detect_us), the tag found
// there and posed through that pinhole camera.
//
// The pixels. The AprilTag library's pixel centres lie at (i + 1/2, j + 1/2), half a pixel right
// of and below ViSP's (and ours); ViSP 3.5 hands its corners to the pose with the camera as it
// is, which biases the pose by half a pixel (0.115 % of the distance, median). The camera
// handed to getPose has its principal point moved by that half pixel, which poses the corners
// where they are.
//
// The rest: detect(), then getPose() of the largest tag 36h11 of id 0 (the bench photographs
// include ViSP's AprilTag test image) with the black side as tagSize: what detect(I, tagSize,
// cam, cMo_vec) does for every tag. The library's defaults (quad_decimate 2, refine_edges on,
// decode_sharpening 0.25, one thread, as our tracker runs).
#pragma once

#include <memory>

#include "detector/lens.h"
#include "eval/rendered/marker_method.h"

namespace oal {

/// The AprilTag's black side on `sheet`'s board, metres: 8/9.5 of its short side.
double AprilTagBlackSide(const LineTarget& sheet);

/// The method for frames of width x height pixels from `camera`.
std::unique_ptr<MarkerMethod> MakeAprilTagMethod(const LineTarget& sheet, const Lens& camera,
                                                 int width, int height);

}  // namespace oal
