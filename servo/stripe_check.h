// The model check: does the image show the target's stripes where a pose puts them?
//
// Each stripe is sampled at `samples` places spread over the part of it in view, off the
// crossings. At each, the grey levels across the stripe are read from beyond one edge to beyond
// the other (a profile, sampled about every pixel, through the lens), and the sample says one of
// three things:
//   - agrees: the profile has the stripe's dark run where the pose puts it: light paper on both
//     sides, and a run darker than both by min_contrast whose middle is within the tolerance of
//     the stripe's projected centre line and whose width is within width_tolerance of the
//     stripe's projected width; or a wider dark run (the stripe and something dark lying against
//     it: a pen, a finger, a shadow) one of whose edges is where the stripe's edge is;
//   - contradicts: the stripe is visible but not there (a dark run with paper on both sides,
//     off by more than the tolerance, or as wide as no stripe and neither edge in place), or
//     there is only paper where the ink should be (the profile light and flat, as light as the
//     paper of the samples that agree) and no sample next to it along the stripe agrees;
//   - tells nothing: something covers the place (a hand, a tool, a cable, a dark shadow: no
//     paper on one side; a flat profile darker than the paper; paper where the ink should be
//     next to a sample that agrees, through samples that tell nothing: something as light as
//     the paper over the stripe, as a pose that agrees to a pixel at one sample is a few
//     pixels off at the next, its ink still in the profile; a dark run narrower than the
//     stripe, inside it, one of its edges where the stripe's is: a pen or a cable lighter than
//     ink across the rest of it), a glare washes it out (the
//     profile saturates where the sheet's paper does not, or is lit well above that paper), or
//     it is out of view.
// Each edge of a dark run lies halfway between the darkest point and the paper on its own side
// (under a glare's or a shadow's slope the paper is lighter on one side, and the ink with it).
// A short run of contradicting samples (two, or a third of the stripe's) that ends, along the
// stripe, at one that tells nothing or at the end of its samples lies at the rim of what covers
// it (a finger's edge crossing the profile leaves a partial dark run; a pale hand over the
// stripe's end passes for paper): excused. A run between agreeing samples is not, nor a whole
// stripe contradicted (a pose turned by 180 degrees).
// How dark a run must be is set by the frame: half the median contrast of its profiles, at
// least min_contrast (the texture of a hand or a tool is no stripe).
// A pose a degree or two off moves the far end of a stripe by several pixels off its ink; an
// occluder only hides stretches. So a right pose under a hand has samples that tell nothing and
// a few that contradict (a light occluder looks like paper), and a wrong pose has samples that
// contradict along whole stripes.
#pragma once

#include <visp3/core/vpHomogeneousMatrix.h>

#include <array>

#include "detector/image_view.h"
#include "detector/lens.h"
#include "servo/target_layout.h"

namespace oal {

struct StripeCheckOptions {
  /// Samples per stripe, over the part of it in view. Range [4, 256].
  int samples = 16;
  /// A stripe is darker than the paper beside it by at least this, grey levels. Range [1, 255].
  int min_contrast = 20;
  /// A sample's dark run agrees when its middle is within the larger of these of the stripe's
  /// projected centre line: pixels, and a fraction of the stripe's projected width. Ranges
  /// (0, 100], [0, 1].
  double centre_tolerance_px = 1.0;
  double centre_tolerance_fraction = 0.1;
  /// ... and its width within this fraction of the stripe's projected width. Range (0, 10].
  double width_tolerance = 0.35;
  /// Where a sample's profile (a stripe's width of paper either side) would leave the image,
  /// a shorter one, half a stripe's width either side: a stripe running along the image's
  /// edge is read too. false: such a sample is not read (a pose that rests on fewer
  /// measurements, fitted to the stripes alone, is held to the full profiles).
  bool short_profiles_at_edge = true;
  /// A profile's points lie about this far apart along it, pixels: one at the focal length the
  /// settings were set for, more for a camera whose stripes are as many more pixels wide (the
  /// tolerances in pixels grow with them; a profile's cost stays that of its paper and ink, not
  /// of the image's size). Range [0.25, 16].
  double profile_step_px = 1.0;

  /// Throws std::invalid_argument naming the field, its value and the violated constraint.
  void Check() const;
};

/// What the samples of each of lines 1-4 said.
struct StripeAgreement {
  std::array<int, 4> samples{};  ///< per line 1-4, in view
  std::array<int, 4> dark{};     ///< ... that agree (the stripe's dark run where the pose puts it)
  std::array<int, 4> contradict{};  ///< ... that contradict the pose
  /// ... that contradict it at the rim of something covering the stripe (a short run next to
  /// a sample that tells nothing, or at an end of its samples), not counted against it.
  std::array<int, 4> excused{};
  /// ... the RMS, over the agreeing samples, of the shift both edges of their dark run share
  /// (the smaller of the two edges' offsets from the stripe's where they lie off the same way),
  /// pixels: a pose a little off moves both of a stripe's edges; something light or dark lying
  /// along one side of the stripe moves one.
  std::array<double, 4> shift_rms_px{};
  /// The same over all agreeing samples.
  double ShiftRms() const;
  /// The smallest, over lines 1-4, of the samples agreeing among those that agree or
  /// contradict (0 for a line with fewer than 3 agreeing samples): 1 when no sample
  /// contradicts.
  double Worst() const;
  /// Of all the samples in view, the fraction that agree.
  double Seen() const;
  /// The one line (0-3) with fewer than 3 agreeing samples and none contradicting (hidden under
  /// something, or out of view) while each other line has 3 or more and agrees in at least
  /// `min_agreement` of the samples that agree or contradict; -1 when there is no such line.
  int Unseen(double min_agreement) const;
};

/// The model check of `layout` at cMo in `image` (`camera`'s lens: distorted pixels).
StripeAgreement CheckStripes(const GrayImageView& image, const TargetLayout& layout,
                             const vpHomogeneousMatrix& cMo, const Lens& camera,
                             const StripeCheckOptions& options = {});

}  // namespace oal
