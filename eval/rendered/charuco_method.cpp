#include "eval/rendered/charuco_method.h"

#include <visp3/core/vpRotationMatrix.h>
#include <visp3/core/vpThetaUVector.h>
#include <visp3/core/vpTranslationVector.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <opencv2/aruco.hpp>
#include <opencv2/aruco/charuco.hpp>
#include <vector>

#include "base/clock.h"
#include "base/format.h"
#include "detector/lens.h"

namespace oal {
namespace {

constexpr int kSquaresX = 10, kSquaresY = 7;
constexpr double kMarkerOverSquare = 0.75;
constexpr double kA3SquareM = 0.038;
constexpr int kPixelsPerSquare = 60;

// `camera_matrix` in the aruco module's pixels, whose centres lie at (i + 1/2, j + 1/2) where
// ours, ViSP's and the rest of OpenCV's (cornerSubPix, calibrateCamera) lie at (i, j): OpenCV
// 4.6's interpolateCornersCharuco moves its corners by -1/2 into cornerSubPix and by +1/2 out
// of it, and estimatePoseCharucoBoard takes them so. The principal point moved by half a pixel
// right and down poses the corners where they are (u - u0 is then the same as in ours).
cv::Matx33d InArucoPixels(cv::Matx33d camera_matrix) {
  camera_matrix(0, 2) += 0.5;
  camera_matrix(1, 2) += 0.5;
  return camera_matrix;
}

class CharucoMethod : public MarkerMethod {
 public:
  CharucoMethod(const LineTarget& sheet, const Lens& camera, int width, int height)
      : square_m_(CharucoSquareSide(sheet)),
        camera_matrix_(InArucoPixels(OpenCvCameraMatrix(camera))),
        distortion_(OpenCvDistortion(camera, width, height)),
        dictionary_(cv::aruco::getPredefinedDictionary(cv::aruco::DICT_5X5_100)),
        board_(cv::aruco::CharucoBoard::create(kSquaresX, kSquaresY, static_cast<float>(square_m_),
                                               static_cast<float>(kMarkerOverSquare * square_m_),
                                               dictionary_)),
        parameters_(cv::aruco::DetectorParameters::create()) {
    cv::Mat drawn;
    board_->draw(cv::Size(kSquaresX * kPixelsPerSquare, kSquaresY * kPixelsPerSquare), drawn, 0, 1);
    auto picture = std::make_shared<vpImage<unsigned char>>(static_cast<unsigned>(drawn.rows),
                                                            static_cast<unsigned>(drawn.cols));
    for (int row = 0; row < drawn.rows; ++row) {
      std::memcpy((*picture)[row], drawn.ptr<unsigned char>(row),
                  static_cast<std::size_t>(drawn.cols));
    }
    print_.picture.image = picture;
    print_.picture.width_m = kSquaresX * square_m_;
    const double hx = 0.5 * kSquaresX * square_m_, hy = 0.5 * kSquaresY * square_m_;
    print_.outline_m = {{{-hx, -hy}, {hx, -hy}, {hx, hy}, {-hx, hy}}};
    print_.description = "ChArUco 10 x 7, DICT_5X5_100, squares " + Fixed(square_m_, 4) +
                         " m, markers " + Fixed(kMarkerOverSquare * square_m_, 4) + " m";
  }

  std::string Name() const override { return "charuco-10x7"; }
  const MarkerPrint& Print() const override { return print_; }

  MarkerPose Find(const vpImage<unsigned char>& image) override {
    MarkerPose result;
    const cv::Mat view(static_cast<int>(image.getHeight()), static_cast<int>(image.getWidth()),
                       CV_8U, image.bitmap);
    auto start = std::chrono::steady_clock::now();
    std::vector<std::vector<cv::Point2f>> markers, rejected;
    std::vector<int> ids;
    cv::aruco::detectMarkers(view, dictionary_, markers, ids, parameters_, rejected);
    std::vector<cv::Point2f> corners;
    std::vector<int> corner_ids;
    if (!ids.empty()) {
      cv::aruco::refineDetectedMarkers(view, board_, markers, ids, rejected, camera_matrix_,
                                       distortion_);
      cv::aruco::interpolateCornersCharuco(markers, ids, view, board_, corners, corner_ids,
                                           camera_matrix_, distortion_);
    }
    result.detect_us = MicrosecondsSince(start);
    if (ids.empty()) {
      result.status = MarkerStatus::kNotFound;
      result.message = "no marker of the board";
      return result;
    }
    start = std::chrono::steady_clock::now();
    cv::Vec3d rvec, tvec;
    const bool posed = corner_ids.size() >= 4 &&
                       cv::aruco::estimatePoseCharucoBoard(corners, corner_ids, board_,
                                                           camera_matrix_, distortion_, rvec, tvec);
    result.pose_us = MicrosecondsSince(start);
    if (!posed) {
      result.status = MarkerStatus::kNoPose;
      result.message = std::to_string(ids.size()) + " marker(s), " +
                       std::to_string(corner_ids.size()) +
                       " chessboard corner(s): the pose needs 4";
      return result;
    }
    // The board's frame: origin at its top-left corner as drawn, x along its columns, y along
    // its rows (OpenCV 4.6), z into the board: the sheet's axes, moved to its centre.
    const vpHomogeneousMatrix cMb(vpTranslationVector(tvec[0], tvec[1], tvec[2]),
                                  vpThetaUVector(rvec[0], rvec[1], rvec[2]));
    vpHomogeneousMatrix bMo;
    bMo[0][3] = 0.5 * kSquaresX * square_m_;
    bMo[1][3] = 0.5 * kSquaresY * square_m_;
    result.status = MarkerStatus::kOk;
    result.cMo = cMb * bMo;
    return result;
  }

 private:
  double square_m_;
  cv::Matx33d camera_matrix_;
  std::vector<double> distortion_;
  cv::Ptr<cv::aruco::Dictionary> dictionary_;
  cv::Ptr<cv::aruco::CharucoBoard> board_;
  cv::Ptr<cv::aruco::DetectorParameters> parameters_;
  MarkerPrint print_;
};

}  // namespace

double CharucoSquareSide(const LineTarget& sheet) {
  return kA3SquareM * std::min(sheet.board_width_m / 0.42, sheet.board_height_m / 0.297);
}

cv::Matx33d OpenCvCameraMatrix(const Lens& camera) {
  return cv::Matx33d(camera.px(), 0.0, camera.u0(), 0.0, camera.py(), camera.v0(), 0.0, 0.0, 1.0);
}

cv::Matx<double, 1, 5> KudAsOpenCvDistortion(const Lens& camera) {
  return cv::Matx<double, 1, 5>(camera.kud(), 0.0, 0.0, 0.0, 0.0);
}

std::vector<double> OpenCvDistortion(const Lens& camera, int width, int height) {
  const Lens opencv = camera.OpenCvCamera(width, height);
  const auto c = opencv.distortion().ToArray();
  return std::vector<double>(c.begin(), c.begin() + (opencv.distortion().IsRational() ? 8 : 5));
}

std::unique_ptr<MarkerMethod> MakeCharucoMethod(const LineTarget& sheet, const Lens& camera,
                                                int width, int height) {
  return std::make_unique<CharucoMethod>(sheet, camera, width, height);
}

}  // namespace oal
