// A line detector or tracker as the comparison runs it (eval/lines/compare.h): ours, ViSP's
// vpMeLine, OpenCV's detectors, or one of the caller's.
#pragma once

#include <visp3/core/vpImage.h>

#include <string>
#include <vector>

#include "detector/line.h"
#include "eval/lines/line_scoring.h"

namespace oal {

/// A line detector or tracker under comparison. The runner calls, per frame:
///   Start(first frame, targets)   once, untimed (a tracker's initialisation)
///   Process(image, lines)         timed: the method's lines, best first, detector/line.h
///                                 convention, in image or (Undistorted()) undistorted pixels
///   AfterFrame(image, targets)    untimed: what a user does after seeing the result (a
///                                 tracker re-initialised after a failure)
/// `targets` are the frame's truth lines, or without truth our detector's first lines
/// (`from_truth` false). An oal-tracker method plugs in here.
class LineMethod {
 public:
  virtual ~LineMethod() = default;
  virtual std::string Name() const = 0;
  /// True when the lines are in undistorted pixels (scored against `ideal_line`).
  virtual bool Undistorted() const { return false; }
  virtual void Start(const vpImage<unsigned char>& /*image*/,
                     const std::vector<TargetLineTruth>& /*targets*/, bool /*from_truth*/) {}
  virtual void Process(const vpImage<unsigned char>& image, std::vector<LineParams>* lines) = 0;
  virtual void AfterFrame(const vpImage<unsigned char>& /*image*/,
                          const std::vector<TargetLineTruth>& /*targets*/, bool /*from_truth*/) {}
  /// Failures and re-initialisations so far; -1 for a method that is not a tracker.
  virtual int failures() const { return -1; }
  virtual int reinitialisations() const { return -1; }
};

}  // namespace oal
