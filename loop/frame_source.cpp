#include "loop/frame_source.h"

#include <cstdint>
#include <utility>

namespace oal {
namespace {

constexpr std::uint64_t kNoiseSeed = 20240605;

}  // namespace

RenderedFrames::RenderedFrames(const LineTarget& target, const RenderOptions& render)
    : renderer_(target, render) {}

bool RenderedFrames::Grab(const vpHomogeneousMatrix& true_cMo, int iteration, cv::Mat* gray) {
  frame_ = renderer_.Render(true_cMo, kNoiseSeed + static_cast<std::uint64_t>(iteration));
  *gray = cv::Mat(static_cast<int>(frame_.image.getHeight()),
                  static_cast<int>(frame_.image.getWidth()), CV_8UC1, frame_.image.bitmap);
  return true;
}

RecordedFrames::RecordedFrames(std::unique_ptr<ImageSource> source) : source_(std::move(source)) {}

bool RecordedFrames::Grab(const vpHomogeneousMatrix& /*true_cMo*/, int /*iteration*/,
                          cv::Mat* gray) {
  if (peeked_ && peeked_error_) {
    // The frame AtEnd() read ahead could not be read: reported here, where it is taken.
    peeked_ = false;
    std::rethrow_exception(std::exchange(peeked_error_, nullptr));
  }
  const bool have_frame = peeked_ ? peeked_frame_ : source_->Next(&frame_);
  peeked_ = false;
  if (!have_frame) return false;
  *gray = frame_.gray;
  return true;
}

bool RecordedFrames::AtEnd() {
  if (!peeked_) {
    try {
      peeked_frame_ = source_->Next(&frame_);
    } catch (const std::exception&) {
      peeked_error_ = std::current_exception();
    }
    peeked_ = true;
  }
  return !peeked_error_ && !peeked_frame_;
}

}  // namespace oal
