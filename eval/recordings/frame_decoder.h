// The first stage of `oalservo evaluate`'s pipeline (eval/recordings/evaluate.h): an input's frames
// read into a bounded queue, each timed, unreadable ones passed on with their error.
#pragma once

#include <atomic>
#include <opencv2/core.hpp>
#include <string>

#include "eval/recordings/pipeline.h"
#include "io/image_source.h"

namespace oal {

/// A frame read, or the error that kept it from being read.
struct DecodedFrame {
  int index = 0;
  cv::Mat gray;  ///< continuous, owned
  std::string source;
  std::string error;  ///< non-empty: the frame could not be read
  double decode_us = 0.0;
};

struct DecodeStats {
  double total_us = 0.0;
  std::string stop_reason;  ///< why reading stopped early ("" at the end of the source)
};

/// Reads `source` (at most max_frames frames; 0: all) into `queue`, then closes it. Gives up
/// after a run of unreadable frames, saying so in stats->stop_reason; stops when `*stop` is
/// set (a viewer's request), saying so too.
void DecodeFrames(ImageSource* source, int max_frames, BoundedQueue<DecodedFrame>* queue,
                  DecodeStats* stats, const std::atomic<bool>* stop = nullptr);

}  // namespace oal
