// A multi-line tracker in ViSP's style (like vpMeLine or vpDot2): initTracking() detects,
// track() follows the lines from frame to frame, display() draws them. It needs no clicks.
//
// Identity. Every line has an id that it keeps while it is tracked. In each frame:
//   1. the lines seen in the previous frame, at their predicted place (constant velocity in
//      rho and theta), seed the detector's accumulator list, so a line that moved less than
//      the matching thresholds (anglechange, rchange) from its prediction collects its votes
//      in the entry of its seed and comes out labelled with the seed's id (OAL-native
//      identity) and goes to its seed's track;
//   2. the other lines (fast motion, reappearing lines) are associated with the remaining
//      tracks, lost ones included, by the gate around each track's prediction, the closest
//      pairs first;
//   3. a detected line left over, with enough support, starts a new track (replacing the
//      track lost the longest when all max_tracks are taken); a track that got no line is `lost`
//      (kept, at its prediction, for `max_lost_frames`, so a line that reappears gets its id
//      back), then dropped.
// When every track is lost the tracker re-detects by itself: each frame runs the detector on
// the whole border scan anyway; no full-image pass is ever made.
//
// Conventions: our lines follow detector/line.h (u = column, v = row,
// u·cosθ + v·sinθ = ρ); getRho()/getTheta() of a TrackedLine give vpMeLine's
// (i = row, j = column, i·cosθ + j·sinθ − ρ = 0).
#pragma once

#include <visp3/core/vpColor.h>
#include <visp3/core/vpImagePoint.h>
#include <visp3/core/vpTracker.h>

#include <optional>
#include <vector>

#include "detector/detector.h"
#include "detector/lens.h"

namespace oal {

enum class TrackStatus {
  kNew,      ///< first seen in this frame
  kTracked,  ///< seen in this frame and before
  kLost,     ///< not seen in this frame; parameters are the prediction
};
const char* ToString(TrackStatus status);

struct TrackerOptions {
  DetectorOptions detector;
  /// Most lines tracked at once (strongest first when more are found). Range [1, 64].
  int max_tracks = 8;
  /// Association gate around a track's prediction: angle, degrees (0, 90], and distance of
  /// the two lines at the image centre, pixels (0, 10000].
  double gate_angle_deg = 10.0;
  double gate_offset_px = 60.0;
  /// A lost track is dropped after this many frames without a line. Range [0, 100000].
  int max_lost_frames = 30;
  /// Seed the accumulator list with the previous frame's lines (step 1 above).
  bool seed_from_previous = true;
  /// A line starts a new track only with at least this many supporting feature points
  /// (DetectedLine::support), so short-lived spurious lines do not become tracks.
  /// Range [0, 100000].
  int min_new_support = 12;

  void Check() const;
};

/// One tracked line.
struct TrackedLine {
  int id = 0;
  TrackStatus status = TrackStatus::kNew;
  DetectedLine line;    ///< the latest measurement, or the prediction when lost
  int frames_seen = 0;  ///< frames with a measurement since the track started
  int frames_lost = 0;  ///< consecutive frames without one

  /// vpMeLine's convention: i·cos(theta) + j·sin(theta) - rho = 0 (i = row, j = column).
  double getRho() const;
  double getTheta() const;
  /// A·i + B·j + C = 0 as vpMeLine::getEquationParam gives it.
  void getEquationParam(double& A, double& B, double& C) const;
  /// Where the line meets the image border (or the undistorted image border).
  void getExtremities(vpImagePoint& ip1, vpImagePoint& ip2) const;
};

class OalLineTracker : public vpTracker {
 public:
  /// Throws std::invalid_argument for options failing Check().
  explicit OalLineTracker(const TrackerOptions& options = TrackerOptions());
  /// With `camera`, feature points are undistorted and lines are in undistorted pixels.
  OalLineTracker(const TrackerOptions& options, const Lens& camera);

  /// Forgets every track and detects the lines of `I` (all of them `new`).
  void initTracking(const vpImage<unsigned char>& I);
  /// Follows the lines into `I`; starts by initTracking() if nothing is tracked.
  void track(const vpImage<unsigned char>& I);
  /// Draws the tracked (not lost) lines with their ids.
  void display(const vpImage<unsigned char>& I, const vpColor& color,
               unsigned int thickness = 1) const;

  const std::vector<TrackedLine>& getLines() const { return tracks_; }
  /// Number of tracks in each status after the last frame.
  int count(TrackStatus status) const;
  /// Time of the last detection, microseconds.
  double lastDetectionTimeUs() const { return last_time_us_; }
  const OalDetector& detector() const { return detector_; }

  /// Intersection of two tracked lines, like vpMeLine::intersection; false when they are
  /// parallel.
  static bool intersection(const TrackedLine& line1, const TrackedLine& line2, vpImagePoint& ip);

 private:
  void Update(const std::vector<DetectedLine>& detected);
  /// The line expected in this frame for track k (constant velocity).
  LineParams Predict(std::size_t k) const;
  double RhoAboutCentre(const LineParams& line) const;
  /// From `before` to `now`: change of rho about the image centre (rho_px) and of theta,
  /// across the 0/pi wrap.
  LineParams Motion(const LineParams& before, const LineParams& now) const;

  TrackerOptions options_;
  OalDetector detector_;
  std::vector<TrackedLine> tracks_;
  std::vector<LineSeed> seeds_;
  /// Per track (same index): change of rho about the image centre and of theta per frame.
  std::vector<LineParams> velocities_;
  int next_id_ = 0;
  double last_time_us_ = 0.0;
  int width_ = 0, height_ = 0;
};

}  // namespace oal
