#include "calibration/chessboard.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "base/check.h"

namespace oal {

void ChessboardOptions::Check() const {
  RequireOption(columns >= 2 && columns <= 100, "ChessboardOptions::columns", columns,
                "2 <= columns <= 100");
  RequireOption(rows >= 2 && rows <= 100, "ChessboardOptions::rows", rows, "2 <= rows <= 100");
  RequireOption(square_m > 0.0 && square_m <= 1.0, "ChessboardOptions::square_m", square_m,
                "0 < square_m <= 1");
}

std::optional<CalibrationView> FindChessboard(const GrayImageView& image,
                                              const ChessboardOptions& options,
                                              const std::string& name) {
  options.Check();
  // A header on the caller's pixels (OpenCV only reads them).
  const cv::Mat gray(image.height, image.width, CV_8UC1, const_cast<std::uint8_t*>(image.data),
                     static_cast<std::size_t>(image.stride));
  const cv::Size pattern(options.columns, options.rows);
  std::vector<cv::Point2f> corners;
  if (!cv::findChessboardCorners(
          gray, pattern, corners,
          cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_FAST_CHECK)) {
    return std::nullopt;
  }
  // The saddle point of each corner, searched within a third of the shortest spacing.
  double spacing = 1e9;
  for (int r = 0; r < options.rows; ++r) {
    for (int c = 0; c + 1 < options.columns; ++c) {
      const cv::Point2f d = corners[static_cast<std::size_t>(r * options.columns + c + 1)] -
                            corners[static_cast<std::size_t>(r * options.columns + c)];
      spacing = std::min(spacing, static_cast<double>(std::hypot(d.x, d.y)));
    }
  }
  const int half = std::clamp(static_cast<int>(spacing / 3.0), 2, 11);
  cv::cornerSubPix(gray, corners, cv::Size(half, half), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-3));
  CalibrationView view;
  view.name = name;
  for (int r = 0; r < options.rows; ++r) {
    for (int c = 0; c < options.columns; ++c) {
      const cv::Point2f& corner = corners[static_cast<std::size_t>(r * options.columns + c)];
      view.points.push_back(
          CalibrationPoint{corner.x, corner.y, c * options.square_m, r * options.square_m});
    }
  }
  return view;
}

}  // namespace oal
