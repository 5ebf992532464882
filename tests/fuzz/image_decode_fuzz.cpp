// Image bytes decoded as every frame source decodes them (the truncation checks, then
// OpenCV's decoders): a bad file is a std::exception with a message, never a crash.
#include <cstdint>
#include <exception>
#include <vector>

#include "io/image_source.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // Larger inputs only slow the search down: the decoders' state machines are reached early.
  if (size > 65536) return 0;
  try {
    const cv::Mat gray =
        oal::DecodeGrayImage(std::vector<unsigned char>(data, data + size), "fuzz");
    if (gray.empty() || gray.type() != CV_8UC1) __builtin_trap();
  } catch (const std::exception&) {
  }
  return 0;
}
