// Chessboard views rendered through a known lens, for the calibration tests (here and in
// tests/app): a printed board on white paper as the renderer's surface texture.
#pragma once

#include <visp3/core/vpMath.h>

#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "calibration/calibrate.h"
#include "calibration/chessboard.h"
#include "detector/image_view.h"
#include "scene/scene.h"

namespace oal::test {

constexpr int kColumns = 9, kRows = 6;  // inner corners
constexpr double kSquareM = 0.02;
constexpr int kTexelsPerSquare = 24;
constexpr int kMarginSquares = 8;  // white paper around the board, so the tiling stays out of view

// A printed chessboard as the surface's texture (the renderer's `background`): the board's
// first inner corner at plane point (corner_m, corner_m).
inline std::shared_ptr<const vpImage<unsigned char>> ChessboardTexture() {
  const int squares_x = kColumns + 1, squares_y = kRows + 1;
  const int width = (squares_x + 2 * kMarginSquares) * kTexelsPerSquare;
  const int height = (squares_y + 2 * kMarginSquares) * kTexelsPerSquare;
  auto texture = std::make_shared<vpImage<unsigned char>>(height, width, 230);
  for (int j = 0; j < squares_y * kTexelsPerSquare; ++j) {
    for (int i = 0; i < squares_x * kTexelsPerSquare; ++i) {
      if (((i / kTexelsPerSquare) + (j / kTexelsPerSquare)) % 2 == 0) {
        (*texture)[j + kMarginSquares * kTexelsPerSquare][i + kMarginSquares * kTexelsPerSquare] =
            30;
      }
    }
  }
  return texture;
}

constexpr double kCornerM = (kMarginSquares + 1) * kSquareM;
constexpr double kCentreXM = kCornerM + 0.5 * (kColumns - 1) * kSquareM;
constexpr double kCentreYM = kCornerM + 0.5 * (kRows - 1) * kSquareM;

// The camera `distance_m` from the board's centre, tilted about the board's x and y axes and
// rolled about its optical axis.
inline vpHomogeneousMatrix LookingAtTheBoard(double distance_m, double tilt_x_deg,
                                             double tilt_y_deg, double roll_deg) {
  return vpHomogeneousMatrix(0, 0, distance_m, 0, 0, 0) *
         vpHomogeneousMatrix(0, 0, 0, 0, 0, vpMath::rad(roll_deg)) *
         vpHomogeneousMatrix(0, 0, 0, vpMath::rad(tilt_x_deg), 0, 0) *
         vpHomogeneousMatrix(0, 0, 0, 0, vpMath::rad(tilt_y_deg), 0) *
         vpHomogeneousMatrix(-kCentreXM, -kCentreYM, 0, 0, 0, 0);
}

// The chessboard seen through `camera` from `cMo` (noise 4 grey levels, blur 1 px).
inline vpImage<unsigned char> RenderChessboard(const Lens& camera, const vpHomogeneousMatrix& cMo,
                                               std::uint64_t seed) {
  LineTarget blank;  // the renderer's board: a speck of paper far from the chessboard
  blank.name = "blank";
  blank.board_width_m = blank.board_height_m = 0.001;
  blank.board_grey = 230;
  RenderOptions render;
  render.camera = camera;
  render.noise_sigma = 4.0;
  render.blur_sigma_px = 1.0;
  render.background = ChessboardTexture();
  render.background_texel_m = kSquareM / kTexelsPerSquare;
  return SceneRenderer(blank, render).Render(cMo, seed).image;
}

inline ChessboardOptions TestChessboard() {
  ChessboardOptions chessboard;
  chessboard.columns = kColumns;
  chessboard.rows = kRows;
  chessboard.square_m = kSquareM;
  return chessboard;
}

// Renders the chessboard through `camera` from each pose and finds it in every view.
inline std::vector<CalibrationView> RenderedViews(const Lens& camera,
                                                  const std::vector<vpHomogeneousMatrix>& poses) {
  std::vector<CalibrationView> views;
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const vpImage<unsigned char> image = RenderChessboard(camera, poses[k], 100 + k);
    const std::string name = "view " + std::to_string(k);
    std::optional<CalibrationView> view = FindChessboard(ViewOf(image), TestChessboard(), name);
    views.push_back(view ? *view : CalibrationView{name, {}, {}});
  }
  return views;
}

// Twelve views 0.35-0.6 m away (the board fills a third to two thirds of the image's width),
// tilted 15-40 deg in different directions, rolled.
inline std::vector<vpHomogeneousMatrix> VariedPoses() {
  std::vector<vpHomogeneousMatrix> poses;
  for (int k = 0; k < 12; ++k) {
    const double angle = 30.0 * k;
    const double tilt = 15.0 + 25.0 * ((k * 7) % 12) / 11.0;
    poses.push_back(LookingAtTheBoard(0.35 + 0.25 * ((k * 5) % 12) / 11.0,
                                      tilt * std::cos(vpMath::rad(angle)),
                                      tilt * std::sin(vpMath::rad(angle)), 20.0 * k - 110.0));
  }
  return poses;
}

// Eight views 0.35 m away with the board near each corner and each edge of a 640 x 480 image
// of focal length `focal_px` (a lens's outer part is told only by views that reach it),
// tilted 20 deg towards the image's centre (towards the corners, untilted).
inline std::vector<vpHomogeneousMatrix> CornerPoses(double focal_px) {
  std::vector<vpHomogeneousMatrix> poses;
  constexpr double kDistanceM = 0.35;
  const double reach_u = 0.7 * 320.0 / focal_px, reach_v = 0.45 * 240.0 / focal_px;
  for (int k = 0; k < 8; ++k) {
    const double angle = vpMath::rad(45.0 * k);
    const double su = std::fabs(std::cos(angle)) < 1e-9 ? 0.0 : (std::cos(angle) > 0 ? 1.0 : -1.0);
    const double sv = std::fabs(std::sin(angle)) < 1e-9 ? 0.0 : (std::sin(angle) > 0 ? 1.0 : -1.0);
    // Towards the corners the board is kept nearer the middle and untilted, so it stays whole.
    const bool diagonal = su != 0.0 && sv != 0.0;
    const double reach = diagonal ? 0.75 : 1.0, tilt = diagonal ? 0.0 : 20.0;
    poses.push_back(vpHomogeneousMatrix(reach * su * reach_u * kDistanceM,
                                        reach * sv * reach_v * kDistanceM, 0, 0, 0, 0) *
                    LookingAtTheBoard(kDistanceM, tilt * sv, -tilt * su, 10.0 * k));
  }
  return poses;
}

}  // namespace oal::test
