// The OAL detector (the paper's image borders) and the target tracker (sheet finder, borders
// on the target's plane, pose, model check) on arbitrary grey images: the first two bytes give
// the size (16..335 x 16..255), the rest the pixels, repeated to fill the image. Whatever the
// image, they return lines and a pose or none, never crash; a pose they return is finite.
#include <cmath>
#include <cstdint>
#include <vector>

#include "detector/detector.h"
#include "scene/scene.h"
#include "servo/target_tracker.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 3) return 0;
  const int width = 16 + data[0] % 320, height = 16 + data[1];
  std::vector<std::uint8_t> pixels(static_cast<std::size_t>(width) * height);
  for (std::size_t i = 0; i < pixels.size(); ++i) pixels[i] = data[2 + i % (size - 2)];
  const oal::GrayImageView image{pixels.data(), width, height, width};

  const oal::Lens camera = oal::Lens::WithKdu(0.9 * width, 0.9 * width, 0.5 * (width - 1),
                                              0.5 * (height - 1), 0.15, width, height);
  oal::OalDetector detector(oal::DetectorOptions(), camera);
  for (const oal::DetectedLine& line : detector.Detect(image)) {
    if (!std::isfinite(line.line.rho_px) || !std::isfinite(line.line.theta_rad)) __builtin_trap();
  }
  oal::PoseOptions pose;
  pose.compute_covariance = false;
  oal::TargetPoseTracker tracker(oal::FourLineA3Target(), camera, oal::DetectorOptions(), pose);
  const oal::TargetFrame& frame = tracker.Track(image);
  if (frame.status == oal::TargetStatus::kOk) {
    for (unsigned i = 0; i < 4; ++i) {
      for (unsigned j = 0; j < 4; ++j) {
        if (!std::isfinite(frame.pose.cMo[i][j])) __builtin_trap();
      }
    }
  }
  return 0;
}
