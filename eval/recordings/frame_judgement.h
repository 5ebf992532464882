// How `oalservo evaluate` (eval/recordings/evaluate.h) judges a frame: its status, a pose that
// jumped from the last trusted one, and how bad the frame is for the report's thumbnails.
#pragma once

#include <visp3/core/vpHomogeneousMatrix.h>

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "servo/pose.h"

namespace oal {

/// A pose is flagged as a jump when, against the last trusted pose of at most kJumpFrames
/// frames before, the same four tracks are identified as other target lines, or the rotation
/// exceeds kJumpRotationDeg (docs/EVALUATE.md, frames.jsonl).
inline constexpr int kJumpFrames = 10;
inline constexpr double kJumpRotationDeg = 90.0;

/// A frame's status; its number is what the report's status plot draws.
enum class FrameStatus : int {
  kUnreadable = -1,
  kLost = 0,      ///< no line held
  kPartial = 1,   ///< some lines held, fewer than the target's
  kDetected = 2,  ///< the target's lines held, no pose
  kPose = 3,      ///< a pose
};

/// "unreadable", "lost", "partial", "detected", "pose".
std::string ToString(FrameStatus status);

/// The track ids identified as target lines 1-4 (-1: not identified).
std::array<int, 4> IdentifiedTracks(const PoseResult& pose, const std::vector<int>& ids);

/// An ok pose and the tracks it identified: the reference against which jumps are found.
struct TrustedPose {
  int frame = 0;
  vpHomogeneousMatrix cMo;
  std::array<int, 4> tracks{};
};

/// A pose that jumped from the last trusted one (kJumpFrames, kJumpRotationDeg).
struct PoseJump {
  int from_frame = 0;
  double rotation_deg = 0.0, translation_mm = 0.0;
  bool relabelled = false;  ///< the same four tracks, identified as other target lines
};

/// What a frame's thumbnail is chosen by.
struct FrameJudgement {
  FrameStatus status = FrameStatus::kLost;
  std::size_t held = 0;              ///< lines held
  const PoseResult* pose = nullptr;  ///< none without a camera
  std::optional<PoseJump> jump;
  int missed = 0;                                       ///< truth lines not found
  double worst_offset_px = 0.0;                         ///< of the truth lines found
  std::optional<std::pair<double, double>> pose_error;  ///< mm, deg
  bool truth_known = false;
};

/// How bad a frame is, for the thumbnails (lost > partial > pose jump > no pose > truth
/// errors), and why, in words.
void Judge(const FrameJudgement& frame, double* badness, std::string* why_text);

/// The jump of the pose cMo of `frame`, identifying `tracks`, from the trusted pose; nothing
/// when there is no trusted pose of at most kJumpFrames before, or no jump.
std::optional<PoseJump> JumpFrom(const std::optional<TrustedPose>& trusted, int frame,
                                 const vpHomogeneousMatrix& cMo, const std::array<int, 4>& tracks);

}  // namespace oal
