// OpenCV's line detectors as compared methods (eval/lines/compare.h): HoughLines on Canny edges or
// on an Otsu threshold, HoughLinesP, LSD and the FastLineDetector. Edges become centre lines
// as docs/COMPARE.md says: segments merged into lines, ranked by length, and a stripe's two
// edges paired into its midline.
#pragma once

#include <memory>

#include "detector/options.h"
#include "eval/lines/line_method.h"

namespace oal {

enum class OpenCvLineDetector { kHoughCanny, kHoughOtsu, kHoughP, kLsd, kFld };

/// Every OpenCvLineDetector, in the comparison's order.
constexpr OpenCvLineDetector kOpenCvLineDetectors[] = {
    OpenCvLineDetector::kHoughCanny, OpenCvLineDetector::kHoughOtsu, OpenCvLineDetector::kHoughP,
    OpenCvLineDetector::kLsd, OpenCvLineDetector::kFld};

/// `kind` as a method. `stripes`: pair edges into centre lines, at most max_stripe_width_px
/// apart, of the stripes' `polarity`; `detector`: its near-duplicate bounds are applied to
/// the lines found, as our read-off applies them.
std::unique_ptr<LineMethod> MakeOpenCvMethod(OpenCvLineDetector kind, bool stripes,
                                             Polarity polarity, double max_stripe_width_px,
                                             const DetectorOptions& detector);

}  // namespace oal
