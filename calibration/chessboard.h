// A printed chessboard in a grey image, as views for calibrate.h: OpenCV's corner finder, then
// its sub-pixel refinement on the saddle points.
#pragma once

#include <optional>
#include <string>

#include "calibration/calibrate.h"
#include "detector/image_view.h"

namespace oal {

struct ChessboardOptions {
  int columns = 9;          ///< inner corners along a row, [2, 100]
  int rows = 6;             ///< inner corners along a column, [2, 100]
  double square_m = 0.025;  ///< a square's side as printed, metres, (0, 1]

  /// Throws std::invalid_argument naming the field, its value and the violated constraint.
  void Check() const;
};

/// The chessboard's inner corners in `image` (sub-pixel, distorted pixels) with their
/// positions on the board, corner (0, 0) at the origin, rows along x; nothing when the whole
/// board is not found (partly out of view, blurred, too small).
std::optional<CalibrationView> FindChessboard(const GrayImageView& image,
                                              const ChessboardOptions& options,
                                              const std::string& name);

}  // namespace oal
