#include "detector/tracker.h"

#include <visp3/core/vpDisplay.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include "base/angles.h"
#include "detector/lens.h"

namespace oal {
namespace {

// The detector's line for a track that has none this frame: the prediction, with its ends.
DetectedLine PredictedLine(const LineParams& line, int width, int height) {
  DetectedLine predicted;
  predicted.line = line;
  ClipToRect(line, 0.0, 0.0, width - 1.0, height - 1.0, &predicted.end_a, &predicted.end_b);
  return predicted;
}

}  // namespace

const char* ToString(TrackStatus status) {
  switch (status) {
    case TrackStatus::kNew:
      return "new";
    case TrackStatus::kTracked:
      return "tracked";
    case TrackStatus::kLost:
      return "lost";
  }
  return "?";
}

void TrackerOptions::Check() const {
  detector.Check();
  auto require = [](bool ok, const std::string& field, double value, const char* constraint) {
    RequireOption(ok, "TrackerOptions::" + field, value, constraint);
  };
  require(max_tracks >= 1 && max_tracks <= 64, "max_tracks", max_tracks, "1 <= max_tracks <= 64");
  require(gate_angle_deg > 0 && gate_angle_deg <= 90, "gate_angle_deg", gate_angle_deg,
          "0 < gate_angle_deg <= 90");
  require(gate_offset_px > 0 && gate_offset_px <= 10000, "gate_offset_px", gate_offset_px,
          "0 < gate_offset_px <= 10000");
  require(min_new_support >= 0 && min_new_support <= 100000, "min_new_support", min_new_support,
          "0 <= min_new_support <= 100000");
  require(max_lost_frames >= 0 && max_lost_frames <= 100000, "max_lost_frames", max_lost_frames,
          "0 <= max_lost_frames <= 100000");
}

double TrackedLine::getRho() const {
  return ToMeLineConvention(line.line).rho_px;
}
double TrackedLine::getTheta() const {
  return ToMeLineConvention(line.line).theta_rad;
}

void TrackedLine::getEquationParam(double& A, double& B, double& C) const {
  const LineParams me = ToMeLineConvention(line.line);
  A = std::cos(me.theta_rad);
  B = std::sin(me.theta_rad);
  C = -me.rho_px;
}

void TrackedLine::getExtremities(vpImagePoint& ip1, vpImagePoint& ip2) const {
  ip1.set_uv(line.end_a.u, line.end_a.v);
  ip2.set_uv(line.end_b.u, line.end_b.v);
}

OalLineTracker::OalLineTracker(const TrackerOptions& options)
    : options_((options.Check(), options)), detector_(options.detector) {}

OalLineTracker::OalLineTracker(const TrackerOptions& options, const Lens& camera)
    : options_((options.Check(), options)), detector_(options.detector, camera) {}

void OalLineTracker::initTracking(const vpImage<unsigned char>& I) {
  tracks_.clear();
  velocities_.clear();
  track(I);
}

void OalLineTracker::track(const vpImage<unsigned char>& I) {
  width_ = static_cast<int>(I.getWidth());
  height_ = static_cast<int>(I.getHeight());
  seeds_.clear();
  if (options_.seed_from_previous) {
    // Only lines seen in the last frame: a lost track's prediction drifts, and a seed there
    // would gather stray votes. Lost tracks come back through the gate instead.
    for (std::size_t k = 0; k < tracks_.size(); ++k) {
      if (tracks_[k].status != TrackStatus::kLost) seeds_.push_back({tracks_[k].id, Predict(k)});
    }
  }
  const auto start = std::chrono::steady_clock::now();
  const std::vector<DetectedLine>& detected = detector_.Detect(ViewOf(I), seeds_);
  last_time_us_ =
      std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
  Update(detected);
}

double OalLineTracker::RhoAboutCentre(const LineParams& line) const {
  return line.rho_px - 0.5 * (width_ - 1) * std::cos(line.theta_rad) -
         0.5 * (height_ - 1) * std::sin(line.theta_rad);
}

LineParams OalLineTracker::Predict(std::size_t k) const {
  const LineParams& last = tracks_[k].line.line;
  const LineParams& velocity = velocities_[k];
  const double theta = last.theta_rad + velocity.theta_rad;
  const double rho_centre = RhoAboutCentre(last) + velocity.rho_px;
  // Back to the top-left origin at the predicted angle.
  return Normalized(
      rho_centre + 0.5 * (width_ - 1) * std::cos(theta) + 0.5 * (height_ - 1) * std::sin(theta),
      theta);
}

LineParams OalLineTracker::Motion(const LineParams& before, const LineParams& now) const {
  double dtheta = now.theta_rad - before.theta_rad;
  double sign = 1.0;  // -1 when the two thetas sit on opposite sides of the 0/pi wrap
  if (dtheta > kPi / 2.0) {
    dtheta -= kPi;
    sign = -1.0;
  } else if (dtheta < -kPi / 2.0) {
    dtheta += kPi;
    sign = -1.0;
  }
  return LineParams{RhoAboutCentre(now) - sign * RhoAboutCentre(before), dtheta};
}

void OalLineTracker::Update(const std::vector<DetectedLine>& detected) {
  // Candidate (track, line) pairs inside the gate, closest first.
  struct Pair {
    double cost;
    std::size_t track, line;
  };
  std::vector<Pair> pairs;
  std::vector<LineParams> predictions(tracks_.size());
  const double gate_angle = options_.gate_angle_deg * kRadPerDeg;
  for (std::size_t k = 0; k < tracks_.size(); ++k) {
    predictions[k] = Predict(k);
    for (std::size_t d = 0; d < detected.size(); ++d) {
      const LineParams motion = Motion(predictions[k], detected[d].line);
      const double angle = std::fabs(motion.theta_rad), offset = std::fabs(motion.rho_px);
      if (angle > gate_angle || offset > options_.gate_offset_px) continue;
      pairs.push_back({angle / gate_angle + offset / options_.gate_offset_px, k, d});
    }
  }
  // A line that grew from a track's seed is that track's, whatever the gate says (the seed
  // matched it within anglechange and rchange); the rest are taken closest first.
  for (std::size_t d = 0; d < detected.size(); ++d) {
    for (std::size_t k = 0; k < tracks_.size(); ++k) {
      if (detected[d].seed_id == tracks_[k].id) pairs.push_back({-1.0, k, d});
    }
  }
  std::stable_sort(pairs.begin(), pairs.end(),
                   [](const Pair& a, const Pair& b) { return a.cost < b.cost; });

  std::vector<bool> track_taken(tracks_.size(), false), line_taken(detected.size(), false);
  for (const Pair& pair : pairs) {
    if (track_taken[pair.track] || line_taken[pair.line]) continue;
    track_taken[pair.track] = line_taken[pair.line] = true;
    TrackedLine& track = tracks_[pair.track];
    // Velocity from two consecutive measurements only.
    velocities_[pair.track] = track.status == TrackStatus::kLost
                                  ? LineParams{0.0, 0.0}
                                  : Motion(track.line.line, detected[pair.line].line);
    track.line = detected[pair.line];
    track.status = TrackStatus::kTracked;
    ++track.frames_seen;
    track.frames_lost = 0;
  }

  // Tracks without a line this frame are lost, at their prediction; old ones are dropped.
  std::size_t kept = 0;
  for (std::size_t k = 0; k < tracks_.size(); ++k) {
    if (!track_taken[k]) {
      TrackedLine& track = tracks_[k];
      track.status = TrackStatus::kLost;
      ++track.frames_lost;
      track.line = PredictedLine(predictions[k], width_, height_);
      velocities_[k] = LineParams{0.0, 0.0};
      if (track.frames_lost > options_.max_lost_frames) continue;
    }
    tracks_[kept] = tracks_[k];
    velocities_[kept] = velocities_[k];
    ++kept;
  }
  tracks_.resize(kept);
  velocities_.resize(kept);

  // Lines nobody claimed start new tracks, strongest first; when every slot is taken, a
  // new line replaces the track lost the longest (a line in view beats a memory).
  for (std::size_t d = 0; d < detected.size(); ++d) {
    if (line_taken[d] || detected[d].support < options_.min_new_support) continue;
    TrackedLine track;
    track.id = next_id_++;
    track.status = TrackStatus::kNew;
    track.line = detected[d];
    track.frames_seen = 1;
    if (static_cast<int>(tracks_.size()) < options_.max_tracks) {
      tracks_.push_back(track);
      velocities_.push_back(LineParams{0.0, 0.0});
      continue;
    }
    const auto oldest = std::max_element(
        tracks_.begin(), tracks_.end(),
        [](const TrackedLine& a, const TrackedLine& b) { return a.frames_lost < b.frames_lost; });
    if (oldest == tracks_.end() || oldest->status != TrackStatus::kLost) break;
    velocities_[static_cast<std::size_t>(oldest - tracks_.begin())] = LineParams{0.0, 0.0};
    *oldest = track;
  }
}

int OalLineTracker::count(TrackStatus status) const {
  return static_cast<int>(
      std::count_if(tracks_.begin(), tracks_.end(),
                    [status](const TrackedLine& t) { return t.status == status; }));
}

void OalLineTracker::display(const vpImage<unsigned char>& I, const vpColor& color,
                             unsigned int thickness) const {
  for (const TrackedLine& track : tracks_) {
    if (track.status == TrackStatus::kLost) continue;
    vpImagePoint a, b;
    track.getExtremities(a, b);
    vpDisplay::displayLine(I, a, b, color, thickness);
    vpDisplay::displayText(
        I, vpImagePoint(0.5 * (a.get_i() + b.get_i()), 0.5 * (a.get_j() + b.get_j())),
        std::to_string(track.id), color);
  }
}

bool OalLineTracker::intersection(const TrackedLine& line1, const TrackedLine& line2,
                                  vpImagePoint& ip) {
  Point2d x;
  if (!Intersect(line1.line.line, line2.line.line, &x)) return false;
  ip.set_uv(x.u, x.v);
  return true;
}

}  // namespace oal
