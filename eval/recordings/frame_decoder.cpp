#include "eval/recordings/frame_decoder.h"

#include <exception>

namespace oal {
namespace {

constexpr int kMaxConsecutiveUnreadable = 50;  // then the input is given up as ended

}  // namespace

void DecodeFrames(ImageSource* source, int max_frames, BoundedQueue<DecodedFrame>* queue,
                  DecodeStats* stats, const std::atomic<bool>* stop) {
  Frame frame;
  int consecutive_errors = 0;
  for (int index = 0; max_frames == 0 || index < max_frames; ++index) {
    if (stop != nullptr && stop->load()) {
      stats->stop_reason = "stopped from the viewer after " + std::to_string(index) + " frames";
      break;
    }
    DecodedFrame item;
    item.index = index;
    bool more = true;
    const StageClock::time_point start = StageClock::now();
    frame.source.clear();  // a failing list of images names its file here
    try {
      more = source->Next(&frame);
    } catch (const std::exception& error) {
      item.error = error.what();
    }
    item.decode_us = Microseconds(StageClock::now() - start);
    stats->total_us += item.decode_us;
    if (!more) break;
    if (item.error.empty()) {
      item.gray = frame.gray.clone();  // the source may reuse its buffer for the next frame
      item.source = frame.source;
      consecutive_errors = 0;
    } else {
      item.source =
          frame.source.empty() ? source->Name() + " frame " + std::to_string(index) : frame.source;
      if (++consecutive_errors > kMaxConsecutiveUnreadable) {
        stats->stop_reason = "gave up after " + std::to_string(kMaxConsecutiveUnreadable) +
                             " consecutive unreadable frames";
        break;
      }
    }
    if (!queue->Push(std::move(item))) break;
  }
  queue->Close();
}

}  // namespace oal
