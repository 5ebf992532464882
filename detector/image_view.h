// A non-owning view of an 8-bit grey image, so that ViSP, OpenCV, V4L2 and video
// buffers reach the detector without a copy.
#pragma once

#include <visp3/core/vpImage.h>

#include <cstddef>
#include <cstdint>

namespace oal {

/// Row-major 8-bit grey pixels; `stride` is the distance in bytes between rows (>= width).
struct GrayImageView {
  const std::uint8_t* data = nullptr;
  int width = 0;
  int height = 0;
  std::ptrdiff_t stride = 0;

  /// Pixel at column u, row v (no bounds check).
  std::uint8_t at(int u, int v) const { return data[static_cast<std::ptrdiff_t>(v) * stride + u]; }
  bool empty() const { return data == nullptr || width <= 0 || height <= 0; }
};

/// View of a ViSP image (contiguous rows).
inline GrayImageView ViewOf(const vpImage<unsigned char>& image) {
  return GrayImageView{image.bitmap, static_cast<int>(image.getWidth()),
                       static_cast<int>(image.getHeight()),
                       static_cast<std::ptrdiff_t>(image.getWidth())};
}

}  // namespace oal
