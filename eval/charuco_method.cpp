#include "eval/charuco_method.h"

#include <visp3/core/vpRotationMatrix.h>
#include <visp3/core/vpThetaUVector.h>
#include <visp3/core/vpTranslationVector.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <opencv2/aruco.hpp>
#include <opencv2/aruco/charuco.hpp>
#include <vector>

#include "base/format.h"
#include "detector/lens.h"

namespace oal {
namespace {

constexpr int kSquaresX = 10, kSquaresY = 7;
constexpr double kMarkerOverSquare = 0.75;
constexpr double kA3SquareM = 0.038;
constexpr int kPixelsPerSquare = 60;

double Microseconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start)
      .count();
}

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
        distortion_(KduAsOpenCvDistortion(camera, width, height)),
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
    result.detect_us = Microseconds(start);
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
    result.pose_us = Microseconds(start);
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
  cv::Matx<double, 1, 5> distortion_;
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

cv::Matx<double, 1, 5> KduAsOpenCvDistortion(const Lens& camera, int width, int height) {
  if (!camera.distorted()) return cv::Matx<double, 1, 5>::zeros();
  if (camera.model() == Lens::Model::kOpenCV && !camera.distortion().IsRational()) {
    const Distortion& d = camera.distortion();
    return cv::Matx<double, 1, 5>(d.k1, d.k2, d.p1, d.p2, d.k3);
  }
  // Minimise over a grid of distorted pixels (u, v) the distance from (u, v) to
  // u0 + px x (1 + k1 r^2 + k2 r^4 + k3 r^6) (and v), (x, y) the ideal point of (u, v) and
  // r^2 = x^2 + y^2: linear in (k1, k2, k3).
  constexpr int kSteps = 40;
  cv::Matx33d normal = cv::Matx33d::zeros();
  cv::Vec3d right(0.0, 0.0, 0.0);
  for (int j = 0; j <= kSteps; ++j) {
    for (int i = 0; i <= kSteps; ++i) {
      const double u = (width - 1.0) * i / kSteps, v = (height - 1.0) * j / kSteps;
      const Point2d ideal = camera.Normalised(u, v);
      const double x = ideal.u, y = ideal.v;
      const double r2 = x * x + y * y;
      const cv::Vec3d powers(r2, r2 * r2, r2 * r2 * r2);
      const cv::Vec3d au = camera.px() * x * powers, av = camera.py() * y * powers;
      const double bu = u - camera.u0() - camera.px() * x;
      const double bv = v - camera.v0() - camera.py() * y;
      normal += au * au.t() + av * av.t();
      right += bu * au + bv * av;
    }
  }
  const cv::Vec3d k = normal.solve(right, cv::DECOMP_CHOLESKY);
  return cv::Matx<double, 1, 5>(k[0], k[1], 0.0, 0.0, k[2]);
}

std::unique_ptr<MarkerMethod> MakeCharucoMethod(const LineTarget& sheet, const Lens& camera,
                                                int width, int height) {
  return std::make_unique<CharucoMethod>(sheet, camera, width, height);
}

}  // namespace oal
