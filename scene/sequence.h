// Rendered sequences with ground truth for comparing line trackers: a camera moving
// in front of a line target, with per-frame effects (occluders, illumination changes), each
// a pure function of (kind, frame count, seed).
//
// Every sequence uses a 640x480 camera with px = py = 600 and the principal point at the
// centre, Gaussian noise sigma = 5 grey levels and blur sigma = 1 px, and by default the 2 m
// four-line board (FourLineTarget(), "four-line-board": the scenarios are designed around its
// '#', in particular which line leaves the image in leave-reenter and where the occluder
// passes; another target, e.g. a sheet, is seen from the same camera poses).
// Motion is given per frame, not per second: speeds in pixels per frame do not depend on the
// frame count, while one-off events (the occluder's pass, the illumination change, the pan
// out and back) are placed relative to the frame count. Scenarios (see MakeSequence for the
// numbers):
//
//   slow           smooth camera motion; lines move about 1-2 px per frame
//   fast           fast shaking motion with roll; lines move 20-40 px per frame
//   occlusion      slow motion; an opaque grey rectangle crosses the image through the
//                  crossing of lines 1 and 2 during the middle 70 % of the frames
//   illumination   slow motion under a 30 % gradient; at frame count / 2 the light drops
//                  (gain 0.5, offset +15 grey levels) and stays low
//   leave-reenter  the camera pans 32 deg sideways and back; the line on that side leaves
//                  the image for the middle part of the sequence and comes back
//   distortion     moderate motion (about 3-5 px per frame) through a lens with kdu = 0.47
//
// Lines keep their target index in the truth (TruthLine::index), so identities are known.
#pragma once

#include <visp3/core/vpHomogeneousMatrix.h>

#include <cstdint>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace oal {

enum class SequenceKind { kSlow, kFast, kOcclusion, kIllumination, kLeaveReenter, kDistortion };

/// "slow", "fast", "occlusion", "illumination", "leave-reenter", "distortion".
const char* ToString(SequenceKind kind);
/// The inverse of ToString; throws std::invalid_argument listing the valid names.
SequenceKind SequenceKindFromString(const std::string& name);
/// Every kind, in the order above.
std::vector<SequenceKind> AllSequenceKinds();
/// The valid names, "slow, fast, ...", for help texts and messages.
std::string SequenceKindNames();

/// One frame of a sequence: what Render(cMo, noise_seed, effects) needs.
struct SequenceFrame {
  vpHomogeneousMatrix cMo;       ///< target (object) frame to camera frame
  FrameEffects effects;          ///< illumination gain/offset and occluders of this frame
  std::uint64_t noise_seed = 0;  ///< distinct per frame
};

/// A scenario ready to render: SceneRenderer(target, options) then, for each frame,
/// Render(frame.cMo, frame.noise_seed, frame.effects).
struct Sequence {
  SequenceKind kind = SequenceKind::kSlow;
  std::uint64_t seed = 0;
  std::string description;  ///< what moves and what happens when, with the numbers
  LineTarget target;
  RenderOptions options;  ///< camera, image size, noise, blur, gradient
  std::vector<SequenceFrame> frames;
};

/// The sequence `kind` of `frame_count` frames (1 <= frame_count <= 100000), seen on
/// `target`. The seed sets the phases and directions of the motion, the initial roll, the
/// occluder's direction, the gradient's direction and the noise; the same arguments give the
/// same sequence on every platform. Events need about 10 frames or more to be seen (e.g. a
/// line leaving and coming back). Throws std::invalid_argument on a bad frame count or an
/// invalid target.
Sequence MakeSequence(SequenceKind kind, int frame_count, std::uint64_t seed,
                      const LineTarget& target = FourLineTarget());

/// How far a line moved between two frames: the mean distance, in pixels, of the two ends
/// and the middle of `from`'s visible part to the line `to.distorted_fit`. Motion along the
/// line does not count. NaN unless both are visible.
double LineDisplacementPx(const TruthLine& from, const TruthLine& to);

}  // namespace oal
