// A lived-in scene: what happens to a printed target on a lab bench from frame to frame, drawn
// per frame from a seed. A hand, a pen, a cable or a tool over part of the sheet; a lamp's
// reflection on the paper; a frame exposed too dark or too bright; the image smeared by the
// camera's motion; a webcam's MJPEG compression. Each condition strikes a given fraction of
// the frames, independently of the others, with its size drawn from a range.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "scene/scene.h"
#include "target/line_target.h"

namespace oal {

/// What lies over the sheet.
enum class OccluderKind {
  kHand,   ///< a palm, five fingers and the forearm, reaching in from outside the sheet
  kPen,    ///< a pen or a screwdriver, 12-17 cm long, 8-14 mm thick, lying anywhere on it
  kCable,  ///< a cable, 4-8 mm thick, winding across the whole sheet
  kTool,   ///< a ruler, a pair of pliers, a phone: a bar or a block 10-20 cm long
};

/// "hand", "pen", "cable", "tool": the one place where the kinds meet strings.
std::string ToString(OccluderKind kind);
/// Throws std::invalid_argument naming the accepted values.
OccluderKind OccluderKindFromString(const std::string& text);

/// A closed range [lo, hi] of a drawn value.
struct DrawRange {
  double lo = 0.0, hi = 0.0;
};

struct LivedInOptions {
  struct Occluders {
    double fraction = 0.0;  ///< of the frames with something over the sheet, [0, 1]
    /// The kinds drawn from, each as likely (a kind listed twice, twice as likely); not empty.
    std::vector<OccluderKind> kinds{OccluderKind::kHand, OccluderKind::kPen, OccluderKind::kCable,
                                    OccluderKind::kTool};
    DrawRange grey{30.0, 220.0};  ///< its grey level, within [0, 255]
    double texture_grey = 12.0;   ///< +- grey levels over it, [0, 100]
    /// A hand or a tool held above the sheet shades it: darkness [0, 0.95] (pens and cables
    /// lie on it and cast none).
    double shadow_darkness = 0.35;
  } occluders;
  struct Glare {
    double fraction = 0.0;           ///< [0, 1]
    DrawRange sigma_m{0.008, 0.03};  ///< its Gaussian's width on the plane, within (0, 1]
    /// Grey levels added at its centre, within [0, 2000]: over about 255 minus the ink's grey
    /// its core saturates ink and paper alike.
    DrawRange peak_grey{200.0, 500.0};
  } glare;
  struct Exposure {
    double fraction = 0.0;  ///< [0, 1]
    /// A dim or a bright frame, as likely: the gain drawn in [lo, (1 + lo) / 2] or in
    /// [(1 + hi) / 2, hi]; lo within [0.05, 1], hi within [1, 4].
    DrawRange gain{1.0 / 3.0, 1.5};
  } exposure;
  struct MotionBlur {
    double fraction = 0.0;           ///< [0, 1]
    DrawRange length_px{3.0, 12.0};  ///< within [0, 200]; in any direction
  } motion_blur;
  struct Jpeg {
    double fraction = 0.0;          ///< [0, 1]
    DrawRange quality{40.0, 90.0};  ///< within [1, 100]
  } jpeg;

  /// Whether any condition strikes any frame.
  bool Any() const;
  /// Throws std::invalid_argument naming the field ("LivedInOptions::glare.fraction"), its
  /// value and the violated constraint.
  void Check() const;
};

/// Frame `frame`'s conditions drawn from `seed` into `effects` (what it already holds stays:
/// its image occluders, noise and blur; its gain is multiplied), for `target` lying in its
/// plane: reproducible, and independent of the other frames and of the order they are drawn
/// in. The objects are placed over the target's board (a hand's palm within it, its forearm
/// reaching out past the board's edge); glares on the board.
void DrawLivedIn(const LivedInOptions& options, const LineTarget& target, std::uint64_t seed,
                 int frame, FrameEffects* effects);

/// The objects of one kind as DrawLivedIn places them, from the generator's uniform draws in
/// [0, 1) (`uniform`): for tests and for scenes that place their own.
PlaneOccluder MakeOccluder(OccluderKind kind, const LineTarget& target, int grey,
                           double texture_grey, double shadow_darkness,
                           const std::function<double()>& uniform);

}  // namespace oal
