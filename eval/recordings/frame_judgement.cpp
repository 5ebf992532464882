#include "eval/recordings/frame_judgement.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <tuple>

#include "eval/recordings/input_truth.h"  // PoseError

namespace oal {

std::string ToString(FrameStatus status) {
  switch (status) {
    case FrameStatus::kUnreadable:
      return "unreadable";
    case FrameStatus::kLost:
      return "lost";
    case FrameStatus::kPartial:
      return "partial";
    case FrameStatus::kDetected:
      return "detected";
    case FrameStatus::kPose:
      return "pose";
  }
  return "unreadable";
}

std::array<int, 4> IdentifiedTracks(const PoseResult& pose, const std::vector<int>& ids) {
  std::array<int, 4> tracks{{-1, -1, -1, -1}};
  for (std::size_t k = 0; k < 4; ++k) {
    const int index = pose.line_index[k];
    if (index >= 0 && index < static_cast<int>(ids.size())) tracks[k] = ids[index];
  }
  return tracks;
}

void Judge(const FrameJudgement& frame, double* badness, std::string* why_text) {
  std::ostringstream why;
  *badness = 0.0;
  if (frame.status == FrameStatus::kLost || frame.status == FrameStatus::kPartial) {
    const bool lost = frame.status == FrameStatus::kLost;
    *badness += lost ? 1000.0 : 500.0;
    why << (lost ? "no line held" : std::to_string(frame.held) + " lines held") << "; ";
  }
  const bool pose_ok = frame.pose != nullptr && frame.pose->status == PoseStatus::kOk;
  if (frame.pose != nullptr && !pose_ok) {
    *badness += 100.0;
    why << "pose " << ToString(frame.pose->status) << "; ";
  }
  if (frame.jump) {
    *badness += 200.0;
    why << "pose jumped " << std::round(frame.jump->rotation_deg * 10.0) / 10.0
        << " deg from frame " << frame.jump->from_frame
        << (frame.jump->relabelled ? " (lines relabelled)" : "") << "; ";
  }
  if (frame.missed > 0) {
    *badness += 50.0 * frame.missed;
    why << frame.missed << " truth line(s) missed; ";
  }
  if (frame.worst_offset_px > 0.0) {
    *badness += frame.worst_offset_px;
    why << "line offset " << std::round(frame.worst_offset_px * 100.0) / 100.0 << " px; ";
  }
  if (frame.pose_error) {
    *badness += frame.pose_error->first / 10.0 + frame.pose_error->second;
    why << "pose error " << std::round(frame.pose_error->first * 10.0) / 10.0 << " mm, "
        << std::round(frame.pose_error->second * 100.0) / 100.0 << " deg; ";
  } else if (pose_ok && !frame.truth_known) {
    *badness += frame.pose->residual_px;
    why << "residual " << std::round(frame.pose->residual_px * 100.0) / 100.0 << " px; ";
  }
  *why_text = why.str();
  if (why_text->size() >= 2) why_text->resize(why_text->size() - 2);
}

std::optional<PoseJump> JumpFrom(const std::optional<TrustedPose>& trusted, int frame,
                                 const vpHomogeneousMatrix& cMo, const std::array<int, 4>& tracks) {
  if (!trusted || frame - trusted->frame > kJumpFrames) return std::nullopt;
  std::array<int, 4> now = tracks, before = trusted->tracks;
  std::sort(now.begin(), now.end());
  std::sort(before.begin(), before.end());
  const bool same_tracks = now == before && now[0] >= 0;
  PoseJump jump;
  jump.from_frame = trusted->frame;
  std::tie(jump.translation_mm, jump.rotation_deg) = PoseError(cMo, trusted->cMo);
  jump.relabelled = same_tracks && tracks != trusted->tracks;
  if (!jump.relabelled && !(jump.rotation_deg > kJumpRotationDeg)) return std::nullopt;
  return jump;
}

}  // namespace oal
