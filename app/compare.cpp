#include "app/compare.h"

#include <visp3/me/vpMe.h>
#include <visp3/me/vpMeLine.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <numeric>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/ximgproc/fast_line_detector.hpp>
#include <sstream>
#include <stdexcept>

#include "app/accuracy_frames.h"  // ConfigHasSection
#include "app/config.h"
#include "app/detector_accuracy.h"
#include "app/frame_command.h"  // CompanionFile
#include "app/truth_file.h"
#include "base/check.h"
#include "base/format.h"
#include "detector/detector.h"
#include "detector/lens.h"
#include "detector/tracker.h"
#include "io/annotate.h"
#include "io/atomic_file.h"
#include "io/camera_file.h"
#include "io/image_source.h"
#include "scene/scene.h"
#include "servo/target_tracker.h"

namespace oal {
namespace {

namespace fs = std::filesystem;

constexpr double kRadToDeg = 180.0 / kPi;

// ---------------------------------------------------------------------------------------
// Line geometry helpers (image pixels, detector/line.h convention).

// The point of `line` nearest to `p`.
Point2d Foot(const LineParams& line, const Point2d& p) {
  const double distance = line.SignedDistance(p.u, p.v);
  return {p.u - distance * std::cos(line.theta_rad), p.v - distance * std::sin(line.theta_rad)};
}

// Distance from `b` of the point of `a` nearest to `centre`: how far apart two nearly
// parallel lines are where it matters (rho alone depends on where the origin is).
double DistanceAt(const LineParams& a, const LineParams& b, const Point2d& centre) {
  const Point2d foot = Foot(a, centre);
  return std::fabs(b.SignedDistance(foot.u, foot.v));
}

// The line half way between two nearly parallel lines.
LineParams Midline(const LineParams& a, const LineParams& b, const Point2d& centre) {
  const Point2d fa = Foot(a, centre), fb = Foot(b, centre);
  double theta_b = b.theta_rad;
  if (theta_b - a.theta_rad > kPi / 2) theta_b -= kPi;
  if (a.theta_rad - theta_b > kPi / 2) theta_b += kPi;
  const double theta = 0.5 * (a.theta_rad + theta_b);
  const double u = 0.5 * (fa.u + fb.u), v = 0.5 * (fa.v + fb.v);
  return Normalized(u * std::cos(theta) + v * std::sin(theta), theta);
}

// Angle (degrees) and offset (larger distance of the chord ends a, b from `line`).
std::pair<double, double> ErrorOf(const LineParams& line, const LineParams& truth, const Point2d& a,
                                  const Point2d& b) {
  return {
      AngleBetween(line, truth) * kRadToDeg,
      std::max(std::fabs(line.SignedDistance(a.u, a.v)), std::fabs(line.SignedDistance(b.u, b.v)))};
}

// Drops lines within `angle_deg` and `distance_px` of a better (earlier) line.
std::vector<LineParams> Deduplicated(const std::vector<LineParams>& lines, double angle_deg,
                                     double distance_px, const Point2d& centre) {
  std::vector<LineParams> kept;
  for (const LineParams& line : lines) {
    const bool duplicate = std::any_of(kept.begin(), kept.end(), [&](const LineParams& k) {
      return AngleBetween(k, line) * kRadToDeg <= angle_deg &&
             DistanceAt(k, line, centre) <= distance_px;
    });
    if (!duplicate) kept.push_back(line);
  }
  return kept;
}

// Pairs the edge lines of stripes into centre lines (see compare.h).
std::vector<LineParams> PairedEdges(const std::vector<LineParams>& lines, double max_width_px,
                                    const Point2d& centre) {
  constexpr double kPairAngleDeg = 2.0, kMinWidthPx = 1.0;
  std::vector<bool> used(lines.size(), false);
  std::vector<LineParams> out;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (used[i]) continue;
    used[i] = true;
    std::size_t best = lines.size();
    double best_distance = max_width_px;
    for (std::size_t j = i + 1; j < lines.size(); ++j) {
      if (used[j] || AngleBetween(lines[i], lines[j]) * kRadToDeg > kPairAngleDeg) continue;
      const double distance = DistanceAt(lines[i], lines[j], centre);
      if (distance >= kMinWidthPx && distance <= best_distance) {
        best = j;
        best_distance = distance;
      }
    }
    if (best == lines.size()) {
      out.push_back(lines[i]);
    } else {
      used[best] = true;
      out.push_back(Midline(lines[i], lines[best], centre));
    }
  }
  return out;
}

// Segments (x1, y1, x2, y2) merged into lines, ranked by total length (see compare.h).
std::vector<LineParams> MergedSegments(const std::vector<cv::Vec4f>& segments) {
  constexpr double kAngleDeg = 1.5, kDistancePx = 1.5;
  struct Cluster {
    LineParams line;
    double length = 0.0;
    double sw = 0.0, su = 0.0, sv = 0.0, suu = 0.0, suv = 0.0, svv = 0.0;  // weighted moments
    void Add(const Point2d& p, double w) {
      sw += w;
      su += w * p.u;
      sv += w * p.v;
      suu += w * p.u * p.u;
      suv += w * p.u * p.v;
      svv += w * p.v * p.v;
    }
    void Refit() {
      const double mu = su / sw, mv = sv / sw;
      const double cuu = suu / sw - mu * mu, cuv = suv / sw - mu * mv, cvv = svv / sw - mv * mv;
      // The normal is the eigenvector of the smaller eigenvalue of the covariance.
      const double direction = 0.5 * std::atan2(2.0 * cuv, cuu - cvv);
      const double theta = direction + kPi / 2;
      line = Normalized(mu * std::cos(theta) + mv * std::sin(theta), theta);
    }
  };
  std::vector<std::pair<double, std::size_t>> order;
  for (std::size_t i = 0; i < segments.size(); ++i) {
    const cv::Vec4f& s = segments[i];
    order.emplace_back(std::hypot(s[2] - s[0], s[3] - s[1]), i);
  }
  std::sort(order.begin(), order.end(), [](const auto& a, const auto& b) { return a > b; });
  std::vector<Cluster> clusters;
  for (const auto& [length, index] : order) {
    const cv::Vec4f& s = segments[index];
    const Point2d a{s[0], s[1]}, b{s[2], s[3]};
    if (length < 1e-6) continue;
    const LineParams own = LineThrough(a, b);
    Cluster* home = nullptr;
    for (Cluster& cluster : clusters) {
      if (AngleBetween(cluster.line, own) * kRadToDeg <= kAngleDeg &&
          std::fabs(cluster.line.SignedDistance(a.u, a.v)) <= kDistancePx &&
          std::fabs(cluster.line.SignedDistance(b.u, b.v)) <= kDistancePx) {
        home = &cluster;
        break;
      }
    }
    if (home == nullptr) {
      clusters.emplace_back();
      home = &clusters.back();
      home->line = own;
    }
    home->Add(a, 0.5 * length);
    home->Add(b, 0.5 * length);
    home->length += length;
    home->Refit();
  }
  std::stable_sort(clusters.begin(), clusters.end(),
                   [](const Cluster& x, const Cluster& y) { return x.length > y.length; });
  std::vector<LineParams> lines;
  for (const Cluster& cluster : clusters) lines.push_back(cluster.line);
  return lines;
}

cv::Mat MatOf(const vpImage<unsigned char>& image) {
  return cv::Mat(static_cast<int>(image.getHeight()), static_cast<int>(image.getWidth()), CV_8UC1,
                 const_cast<unsigned char*>(image.bitmap));
}

// ---------------------------------------------------------------------------------------
// The methods.

class OalMethod : public LineMethod {
 public:
  OalMethod(const DetectorOptions& options, const std::optional<CameraFile>& camera)
      : detector_(camera ? OalDetector(options, camera->camera) : OalDetector(options)) {}
  std::string Name() const override { return "oal"; }
  bool Undistorted() const override { return detector_.Undistorts(); }
  void Process(const vpImage<unsigned char>& image, std::vector<LineParams>* lines) override {
    last_ = &detector_.Detect(image);
    lines->clear();
    for (const DetectedLine& line : *last_) lines->push_back(line.line);
  }
  const std::vector<DetectedLine>& last() const { return *last_; }

 private:
  OalDetector detector_;
  const std::vector<DetectedLine>* last_ = nullptr;
};

// The target tracker (servo/target_tracker.h): the four lines of the pose it accepts, in the
// order of the target's lines; nothing in a frame without an accepted pose (a wrong pose is
// refused, not scored). Its failures are the frames without a pose.
class OalTargetMethod : public LineMethod {
 public:
  OalTargetMethod(const AppConfig& config, const vpCameraParameters& camera)
      : tracker_(config.target, camera, config.detector, PoseOf(config), config.tracking) {}
  std::string Name() const override { return "oal-target"; }
  bool Undistorted() const override { return tracker_.detector().Undistorts(); }
  void Process(const vpImage<unsigned char>& image, std::vector<LineParams>* lines) override {
    const TargetFrame& frame = tracker_.Track(ViewOf(image));
    lines->clear();
    if (frame.status != TargetStatus::kOk) {
      ++failures_;
      return;
    }
    for (const int index : frame.pose.line_index) {
      lines->push_back(tracker_.lines()[static_cast<std::size_t>(index)].line);
    }
  }
  int failures() const override { return failures_; }
  int reinitialisations() const override { return 0; }

 private:
  // The tracker sets the camera and each frame's size itself; scoring needs no covariance.
  static PoseOptions PoseOf(const AppConfig& config) {
    PoseOptions pose = config.pose;
    pose.compute_covariance = false;
    return pose;
  }

  TargetPoseTracker tracker_;
  int failures_ = 0;
};

// Our temporal tracker: the lines it holds in each frame (lost ones excluded), best
// supported first, as the detector ranks them. A user never re-initialises it; its
// failures are the tracks it lost.
class OalTrackerMethod : public LineMethod {
 public:
  OalTrackerMethod(const DetectorOptions& options, const std::optional<CameraFile>& camera)
      : tracker_(Options(options), camera ? camera->camera : vpCameraParameters()) {}
  std::string Name() const override { return "oal-tracker"; }
  bool Undistorted() const override { return tracker_.detector().Undistorts(); }
  void Process(const vpImage<unsigned char>& image, std::vector<LineParams>* lines) override {
    tracker_.track(image);
    held_.clear();
    for (const TrackedLine& track : tracker_.getLines()) {
      if (track.status != TrackStatus::kLost) held_.push_back(&track.line);
    }
    std::stable_sort(held_.begin(), held_.end(), [](const DetectedLine* a, const DetectedLine* b) {
      return a->support > b->support;
    });
    lines->clear();
    for (const DetectedLine* line : held_) lines->push_back(line->line);
  }
  void AfterFrame(const vpImage<unsigned char>& /*image*/,
                  const std::vector<TargetLineTruth>& /*targets*/, bool /*from_truth*/) override {
    for (const TrackedLine& track : tracker_.getLines()) {
      failures_ += track.status == TrackStatus::kLost && track.frames_lost == 1;
    }
  }
  int failures() const override { return failures_; }
  int reinitialisations() const override { return 0; }

 private:
  static TrackerOptions Options(const DetectorOptions& detector) {
    TrackerOptions options;
    options.detector = detector;
    return options;
  }

  OalLineTracker tracker_;
  std::vector<const DetectedLine*> held_;
  int failures_ = 0;
};

// The OpenCV methods, one class: they share the Canny edges, the segment merging and the
// edge pairing.
class OpenCvMethod : public LineMethod {
 public:
  enum class Kind { kHoughCanny, kHoughOtsu, kHoughP, kLsd, kFld };

  OpenCvMethod(Kind kind, bool stripes, Polarity polarity, double max_stripe_width_px,
               const DetectorOptions& detector)
      : kind_(kind),
        stripes_(stripes),
        polarity_(polarity),
        max_stripe_width_px_(max_stripe_width_px),
        duplicate_angle_deg_(detector.duplicate_angle_deg),
        duplicate_r_px_(detector.duplicate_r_px) {
    if (kind_ == Kind::kLsd) lsd_ = cv::createLineSegmentDetector(cv::LSD_REFINE_STD);
    if (kind_ == Kind::kFld) fld_ = cv::ximgproc::createFastLineDetector();
  }

  std::string Name() const override {
    switch (kind_) {
      case Kind::kHoughCanny:
        return "HoughLines (Canny)";
      case Kind::kHoughOtsu:
        return "HoughLines (Otsu)";
      case Kind::kHoughP:
        return "HoughLinesP (Canny)";
      case Kind::kLsd:
        return "LSD";
      case Kind::kFld:
        return "FastLineDetector";
    }
    return "?";
  }

  void Process(const vpImage<unsigned char>& image, std::vector<LineParams>* lines) override {
    const cv::Mat view = MatOf(image);
    const Point2d centre{0.5 * (view.cols - 1), 0.5 * (view.rows - 1)};
    const int size = std::min(view.cols, view.rows);
    const int hough_votes = std::max(20, size / 4);
    std::vector<LineParams> found;
    switch (kind_) {
      case Kind::kHoughCanny: {
        CannyEdges(view);
        HoughPeaks(edges_, hough_votes, &found);
        found = Deduplicated(found, 1.0, 1.5, centre);
        break;
      }
      case Kind::kHoughOtsu: {
        const int type =
            polarity_ == Polarity::kLightLines ? cv::THRESH_BINARY : cv::THRESH_BINARY_INV;
        cv::threshold(view, binary_, 0, 255, type | cv::THRESH_OTSU);
        if (polarity_ == Polarity::kEdges) {  // the boundary of the binary image votes
          cv::erode(binary_, eroded_, cv::Mat());
          cv::subtract(binary_, eroded_, binary_);
        }
        HoughPeaks(binary_, hough_votes, &found);
        *lines = Deduplicated(found, duplicate_angle_deg_, duplicate_r_px_, centre);
        return;  // centre lines (stripes) or edges already: nothing to pair
      }
      case Kind::kHoughP: {
        CannyEdges(view);
        segments_.clear();
        std::vector<cv::Vec4i> segments;
        cv::HoughLinesP(edges_, segments, 1.0, CV_PI / 360.0, std::max(10, size / 8),
                        std::max(10.0, size / 10.0), 5.0);
        for (const cv::Vec4i& s : segments) segments_.emplace_back(s[0], s[1], s[2], s[3]);
        found = MergedSegments(segments_);
        break;
      }
      case Kind::kLsd:
        segments_.clear();
        lsd_->detect(view, segments_);
        found = MergedSegments(segments_);
        break;
      case Kind::kFld:
        segments_.clear();
        fld_->detect(view, segments_);
        found = MergedSegments(segments_);
        break;
    }
    *lines = stripes_ ? PairedEdges(found, max_stripe_width_px_, centre) : std::move(found);
  }

 private:
  void CannyEdges(const cv::Mat& view) {
    cv::GaussianBlur(view, blurred_, cv::Size(5, 5), 1.2);
    cv::Canny(blurred_, edges_, 50, 150);
  }
  static void HoughPeaks(const cv::Mat& binary, int votes, std::vector<LineParams>* lines) {
    std::vector<cv::Vec2f> peaks;  // sorted by votes, best first
    cv::HoughLines(binary, peaks, 1.0, CV_PI / 360.0, votes);
    lines->clear();
    for (const cv::Vec2f& peak : peaks) lines->push_back(Normalized(peak[0], peak[1]));
  }

  Kind kind_;
  bool stripes_;
  Polarity polarity_;
  double max_stripe_width_px_;
  double duplicate_angle_deg_, duplicate_r_px_;
  cv::Ptr<cv::LineSegmentDetector> lsd_;
  cv::Ptr<cv::ximgproc::FastLineDetector> fld_;
  cv::Mat blurred_, edges_, binary_, eroded_;
  std::vector<cv::Vec4f> segments_;
};

// vpMeLine's a·i + b·j + c = 0 (i = row, j = column) in our convention. vpMeLine::getRho()
// takes |c| and picks the sign from the grey levels on both sides (its theta spans
// [0, 2 pi) to carry polarity), so the exact equation is read instead: rho_me = -c with
// theta_me = atan2(b, a), converted by detector/line.h's FromMeLineConvention.
LineParams LineOfMeLine(const vpMeLine& me_line) {
  const double a = me_line.getA(), b = me_line.getB(), c = me_line.getC();
  const double norm = std::hypot(a, b);
  return FromMeLineConvention(LineParams{-c / norm, std::atan2(b, a)});
}

// ViSP 3.5 moving edges: one tracker per target edge, two per stripe (their midline).
class VpMeLineMethod : public LineMethod {
 public:
  VpMeLineMethod(const VpMeLineOptions& options, bool stripes)
      : options_(options), stripes_(stripes) {
    me_.setRange(static_cast<unsigned int>(options.range_px));
    me_.setThreshold(options.threshold);
    me_.setSampleStep(options.sample_step_px);
    me_.setPointsToTrack(500);
    me_.setMaskSize(5);
    me_.setMaskNumber(180);
  }
  std::string Name() const override { return "vpMeLine"; }

  void Start(const vpImage<unsigned char>& image, const std::vector<TargetLineTruth>& targets,
             bool /*from_truth*/) override {
    for (const TargetLineTruth& target : targets) {
      tracks_.emplace_back();
      tracks_.back().id = target.id;
      Initialise(image, target, &tracks_.back());
    }
  }

  void Process(const vpImage<unsigned char>& image, std::vector<LineParams>* lines) override {
    lines->clear();
    const Point2d centre{0.5 * (image.getWidth() - 1.0), 0.5 * (image.getHeight() - 1.0)};
    for (Track& track : tracks_) {
      if (!track.ok) continue;
      try {
        for (auto& edge : track.edges) edge->track(image);
      } catch (const std::exception&) {
        track.ok = false;
        track.threw = true;
        continue;
      }
      track.line = track.edges.size() == 2 ? Midline(LineOfMeLine(*track.edges[0]),
                                                     LineOfMeLine(*track.edges[1]), centre)
                                           : LineOfMeLine(*track.edges[0]);
      lines->push_back(track.line);
    }
  }

  void AfterFrame(const vpImage<unsigned char>& image, const std::vector<TargetLineTruth>& targets,
                  bool from_truth) override {
    const Point2d centre{0.5 * (image.getWidth() - 1.0), 0.5 * (image.getHeight() - 1.0)};
    std::vector<bool> taken(targets.size(), false);
    for (Track& track : tracks_) {
      const TargetLineTruth* target = nullptr;
      if (from_truth) {
        for (std::size_t i = 0; i < targets.size(); ++i) {
          if (targets[i].id == track.id) {
            target = &targets[i];
            taken[i] = true;
          }
        }
      } else {  // our detections: the one nearest to the track's line
        double best = 1e300;
        for (std::size_t i = 0; i < targets.size(); ++i) {
          if (taken[i]) continue;
          const double cost = AngleBetween(targets[i].image_line, track.line) * kRadToDeg / 5.0 +
                              DistanceAt(track.line, targets[i].image_line, centre) / 10.0;
          if (cost < best) {
            best = cost;
            target = &targets[i];
          }
        }
        if (target != nullptr) taken[static_cast<std::size_t>(target - targets.data())] = true;
      }
      bool failed = track.threw;
      if (track.ok && from_truth && target != nullptr) {
        const auto [angle, offset] =
            ErrorOf(track.line, target->image_line, Foot(target->image_line, target->end_a),
                    Foot(target->image_line, target->end_b));
        failed = angle > options_.drift_angle_deg || offset > options_.drift_offset_px;
      }
      track.threw = false;
      if (failed) ++failures_;
      if (target == nullptr) {  // out of view: a user stops tracking it
        track.ok = false;
        continue;
      }
      if (failed || !track.ok) {
        ++reinitialisations_;
        Initialise(image, *target, &track);
      }
    }
    if (!from_truth) return;
    for (std::size_t i = 0; i < targets.size(); ++i) {  // lines coming into view
      if (taken[i]) continue;
      tracks_.emplace_back();
      tracks_.back().id = targets[i].id;
      ++reinitialisations_;
      Initialise(image, targets[i], &tracks_.back());
    }
  }

  int failures() const override { return failures_; }
  int reinitialisations() const override { return reinitialisations_; }

 private:
  struct Track {
    int id = 0;
    std::vector<std::unique_ptr<vpMeLine>> edges;
    bool ok = false;
    bool threw = false;
    LineParams line;
  };

  // What a user clicks: two points on the line (its edges for a stripe), at 10 % and 90 %
  // of its visible chord.
  void Initialise(const vpImage<unsigned char>& image, const TargetLineTruth& target,
                  Track* track) {
    track->edges.clear();
    track->ok = false;
    track->line = target.image_line;
    const Point2d a = Foot(target.image_line, target.end_a);
    const Point2d b = Foot(target.image_line, target.end_b);
    const Point2d p{a.u + 0.1 * (b.u - a.u), a.v + 0.1 * (b.v - a.v)};
    const Point2d q{a.u + 0.9 * (b.u - a.u), a.v + 0.9 * (b.v - a.v)};
    std::vector<double> offsets{0.0};
    if (stripes_ && target.width_px >= 1.5)
      offsets = {-0.5 * target.width_px, 0.5 * target.width_px};
    const double nu = std::cos(target.image_line.theta_rad),
                 nv = std::sin(target.image_line.theta_rad);
    try {
      for (double offset : offsets) {
        auto edge = std::make_unique<vpMeLine>();
        edge->setMe(&me_);
        edge->setDisplay(vpMeSite::NONE);
        const vpImagePoint ip1(p.v + offset * nv, p.u + offset * nu);
        const vpImagePoint ip2(q.v + offset * nv, q.u + offset * nu);
        edge->initTracking(image, ip1, ip2);
        track->edges.push_back(std::move(edge));
      }
      track->ok = true;
    } catch (const std::exception&) {
      track->edges.clear();  // no line until the next re-initialisation
    }
  }

  VpMeLineOptions options_;
  bool stripes_;
  vpMe me_;
  std::vector<Track> tracks_;
  int failures_ = 0;
  int reinitialisations_ = 0;
};

// ---------------------------------------------------------------------------------------
// Truth.

[[noreturn]] void FileError(const std::string& path, int line, const std::string& message) {
  throw std::runtime_error(path + (line > 0 ? ":" + std::to_string(line) : "") + ": " + message);
}

}  // namespace

int FrameNumber(const std::string& source, int position) {
  const std::string name = fs::path(source).filename().string();
  const auto last = name.find_last_of("0123456789");
  if (last == std::string::npos) return position;
  auto first = last;
  while (first > 0 && std::isdigit(static_cast<unsigned char>(name[first - 1]))) --first;
  if (last - first >= 9) return position;
  return std::stoi(name.substr(first, last - first + 1));
}

std::vector<LineMatch> MatchLines(const std::vector<ReferenceLine>& references,
                                  const std::vector<LineParams>& lines, double max_angle_deg,
                                  double max_offset_px) {
  struct Candidate {
    double cost;
    LineMatch match;
  };
  std::vector<Candidate> candidates;
  for (std::size_t r = 0; r < references.size(); ++r) {
    const ReferenceLine& reference = references[r];
    for (std::size_t l = 0; l < lines.size(); ++l) {
      const auto [angle, offset] =
          ErrorOf(lines[l], reference.line, reference.end_a, reference.end_b);
      if (angle <= max_angle_deg && offset <= max_offset_px) {
        candidates.push_back(
            {angle / max_angle_deg + offset / max_offset_px, {r, l, angle, offset}});
      }
    }
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Candidate& x, const Candidate& y) { return x.cost < y.cost; });
  std::vector<bool> reference_used(references.size(), false), line_used(lines.size(), false);
  std::vector<LineMatch> matches;
  for (const Candidate& c : candidates) {
    if (reference_used[c.match.reference] || line_used[c.match.line]) continue;
    reference_used[c.match.reference] = line_used[c.match.line] = true;
    matches.push_back(c.match);
  }
  return matches;
}

namespace {

// The visible chord of a line without one: its clip to the image.
bool ClipChord(TargetLineTruth* truth, int width, int height) {
  return ClipToRect(truth->image_line, 0.0, 0.0, width - 1.0, height - 1.0, &truth->end_a,
                    &truth->end_b);
}

std::vector<TargetLineTruth> TargetsFromDetections(const std::vector<DetectedLine>& detected,
                                                   std::size_t count, bool undistorted,
                                                   const std::optional<CameraFile>& camera,
                                                   int width, int height) {
  std::vector<TargetLineTruth> targets;
  for (std::size_t i = 0; i < detected.size() && targets.size() < count; ++i) {
    TargetLineTruth target;
    target.id = static_cast<int>(i);
    target.width_px = detected[i].width_px;
    target.image_line = target.ideal_line = detected[i].line;
    if (undistorted && camera) {  // back to image pixels: two points through the lens
      const vpCameraParameters& cam = camera->camera;
      auto distort = [&](const Point2d& p) {
        return DistortedPixel(cam, (p.u - cam.get_u0()) / cam.get_px(),
                              (p.v - cam.get_v0()) / cam.get_py());
      };
      const Point2d a = distort(detected[i].end_a), b = distort(detected[i].end_b);
      if (!std::isfinite(a.u) || !std::isfinite(b.u)) continue;
      target.image_line = LineThrough(a, b);
    }
    if (!ClipChord(&target, width, height)) continue;
    targets.push_back(target);
  }
  return targets;
}

// ---------------------------------------------------------------------------------------
// Scoring.

struct Scorer {
  double max_angle_deg, max_offset_px;
  std::optional<PointUndistorter> undistorter;  // ends for the `ideal` reference

  void Score(const std::vector<LineParams>& lines, const std::vector<TargetLineTruth>& truth,
             bool ideal, MethodResult* result) const {
    std::vector<ReferenceLine> references;
    for (const TargetLineTruth& target : truth) {
      const LineParams& reference = ideal ? target.ideal_line : target.image_line;
      const Point2d a = ideal && undistorter ? undistorter->Undistort(target.end_a)
                                             : Foot(reference, target.end_a);
      const Point2d b = ideal && undistorter ? undistorter->Undistort(target.end_b)
                                             : Foot(reference, target.end_b);
      references.push_back({reference, a, b});
    }
    const std::vector<LineMatch> matches =
        MatchLines(references, lines, max_angle_deg, max_offset_px);
    for (const LineMatch& match : matches) {
      result->angle_error_deg.push_back(match.angle_deg);
      result->offset_error_px.push_back(match.offset_px);
    }
    const int found = static_cast<int>(matches.size());
    const int missed = static_cast<int>(truth.size()) - found;
    result->truth_lines += static_cast<int>(truth.size());
    result->found_lines += found;
    result->spurious_lines += static_cast<int>(lines.size()) - found;
    result->missed_per_frame.push_back(missed);
    if (missed == 0) {
      ++result->frames_all_found;
    } else {
      result->missed_frames.push_back(result->frames);
    }
  }
};

double Mean(const std::vector<double>& values) {
  return values.empty() ? 0.0 : std::accumulate(values.begin(), values.end(), 0.0) / values.size();
}

// ---------------------------------------------------------------------------------------
// Figures.

const cv::Scalar kPalette[] = {{0, 0, 255},     {255, 0, 255},  {255, 128, 0}, {0, 160, 255},
                               {0, 200, 0},     {255, 255, 0},  {0, 255, 255}, {160, 110, 255},
                               {128, 255, 128}, {255, 160, 160}};

cv::Mat Figure(const cv::Mat& gray, int frame, const CompareReport& report,
               const std::vector<std::vector<TargetLineTruth>>& truth,
               const std::vector<bool>& undistorted, const std::optional<CameraFile>& camera) {
  cv::Mat figure;
  cv::cvtColor(gray, figure, cv::COLOR_GRAY2BGR);
  const int w = gray.cols, h = gray.rows;
  auto draw = [&](const LineParams& line, bool ideal, const cv::Scalar& colour, int thickness) {
    std::optional<vpCameraParameters> by;
    if (ideal && camera) by = camera->camera;
    for (const auto& polyline : LineInFrame(line, w, h, by)) {
      for (std::size_t i = 1; i < polyline.size(); ++i) {
        cv::line(figure, polyline[i - 1], polyline[i], colour, thickness, cv::LINE_AA);
      }
    }
  };
  for (const TargetLineTruth& target : truth[static_cast<std::size_t>(frame)]) {
    draw(target.image_line, false, cv::Scalar(255, 255, 255), 3);
  }
  for (std::size_t m = 0; m < report.methods.size(); ++m) {
    const auto& lines = report.methods[m].lines[static_cast<std::size_t>(frame)];
    for (const LineParams& line : lines) draw(line, undistorted[m], kPalette[m % 10], 1);
  }
  // Legend, top left.
  const double scale = 0.4;
  const int row = 14;
  std::vector<std::pair<std::string, cv::Scalar>> entries;
  if (!truth[static_cast<std::size_t>(frame)].empty()) {
    entries.emplace_back("truth", cv::Scalar(255, 255, 255));
  }
  for (std::size_t m = 0; m < report.methods.size(); ++m) {
    entries.emplace_back(report.methods[m].name, kPalette[m % 10]);
  }
  cv::rectangle(figure, cv::Rect(0, 0, 170, row * static_cast<int>(entries.size() + 1) + 4),
                cv::Scalar(40, 40, 40), cv::FILLED);
  cv::putText(figure, "frame " + std::to_string(frame), cv::Point(4, row - 2),
              cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const int y = row * static_cast<int>(i + 2) - 2;
    cv::line(figure, cv::Point(4, y - 4), cv::Point(22, y - 4), entries[i].second, 2);
    cv::putText(figure, entries[i].first, cv::Point(28, y), cv::FONT_HERSHEY_SIMPLEX, scale,
                entries[i].second, 1, cv::LINE_AA);
  }
  return figure;
}

std::string FigureName(int frame) {
  std::string number = std::to_string(frame);
  if (number.size() < 4) number.insert(0, 4 - number.size(), '0');
  return "compare_frame_" + number + ".png";
}

void CopyInto(const cv::Mat& gray, vpImage<unsigned char>* image) {
  if (static_cast<int>(image->getWidth()) != gray.cols ||
      static_cast<int>(image->getHeight()) != gray.rows) {
    image->resize(static_cast<unsigned int>(gray.rows), static_cast<unsigned int>(gray.cols));
  }
  for (int r = 0; r < gray.rows; ++r) {
    std::memcpy((*image)[static_cast<unsigned int>(r)], gray.ptr(r),
                static_cast<std::size_t>(gray.cols));
  }
}

// Frame numbers as sorted ranges, "0-2, 5, 7-9", at most `max_ranges` of them then "...".
std::string FrameRanges(std::vector<int> frames, std::size_t max_ranges = 8) {
  std::sort(frames.begin(), frames.end());
  frames.erase(std::unique(frames.begin(), frames.end()), frames.end());
  std::string out;
  std::size_t ranges = 0;
  for (std::size_t i = 0; i < frames.size();) {
    std::size_t j = i;
    while (j + 1 < frames.size() && frames[j + 1] == frames[j] + 1) ++j;
    if (ranges++ == max_ranges) return out + ", ...";
    out += (out.empty() ? "" : ", ") + std::to_string(frames[i]);
    if (j > i) out += "-" + std::to_string(frames[j]);
    i = j + 1;
  }
  return out.empty() ? "none" : out;
}

// The frames on which a method threw an OpenCV error (it then finds no line there).
struct MethodFailure {
  int frames = 0;
  std::string first;  // the first such frame and the error

  void Add(int index, const Frame& frame, const cv::Exception& error) {
    if (frames++ > 0) return;
    first = "frame " + std::to_string(index) + " '" + frame.source + "', " +
            std::to_string(frame.gray.cols) + "x" + std::to_string(frame.gray.rows) +
            " px: OpenCV: " + error.err;
  }
  std::string Warning(const std::string& method) const {
    return method + " could not run on " + std::to_string(frames) + " frame" +
           (frames == 1 ? "" : "s") + " (first: " + first + "); scored as finding no line there";
  }
};

}  // namespace

// ---------------------------------------------------------------------------------------

std::string ToString(TargetKind kind) {
  switch (kind) {
    case TargetKind::kAuto:
      return "auto";
    case TargetKind::kStripes:
      return "stripes";
    case TargetKind::kEdges:
      return "edges";
  }
  return "?";
}

TargetKind TargetKindFromString(const std::string& text) {
  if (text == "auto") return TargetKind::kAuto;
  if (text == "stripes") return TargetKind::kStripes;
  if (text == "edges") return TargetKind::kEdges;
  throw std::invalid_argument("target kind '" + text + "' is not one of auto, stripes, edges");
}

void VpMeLineOptions::Check() const {
  auto require = [](bool ok, const std::string& field, double value, const char* constraint) {
    RequireOption(ok, "VpMeLineOptions::" + field, value, constraint);
  };
  require(range_px >= 1 && range_px <= 100, "range_px", range_px, "1 <= range_px <= 100");
  require(threshold > 0.0, "threshold", threshold, "threshold > 0");
  require(sample_step_px >= 1.0 && sample_step_px <= 100.0, "sample_step_px", sample_step_px,
          "1 <= sample_step_px <= 100");
  require(drift_angle_deg > 0.0, "drift_angle_deg", drift_angle_deg, "drift_angle_deg > 0");
  require(drift_offset_px > 0.0, "drift_offset_px", drift_offset_px, "drift_offset_px > 0");
}

void CompareOptions::Check() const {
  auto require = [](bool ok, const std::string& field, double value, const char* constraint) {
    RequireOption(ok, "CompareOptions::" + field, value, constraint);
  };
  if (input.empty()) throw std::invalid_argument("CompareOptions::input is empty");
  require(lines >= 0 && lines <= 100, "lines", lines, "0 <= lines <= 100");
  require(max_frames >= 0, "max_frames", max_frames, "max_frames >= 0");
  require(max_angle_deg > 0.0, "max_angle_deg", max_angle_deg, "max_angle_deg > 0");
  require(max_offset_px > 0.0, "max_offset_px", max_offset_px, "max_offset_px > 0");
  require(max_stripe_width_px >= 0.0, "max_stripe_width_px", max_stripe_width_px,
          "max_stripe_width_px >= 0");
  require(figures >= 0 && figures <= 10, "figures", figures, "0 <= figures <= 10");
  me.Check();
  if (!out_dir.empty() && fs::exists(out_dir) && !fs::is_directory(out_dir)) {
    throw std::invalid_argument("output '" + out_dir + "' is not a directory");
  }
}

std::map<int, std::vector<TargetLineTruth>> LoadTruthCsv(const std::string& path) {
  return LoadTruthCsvWithPoses(path).lines;
}

std::vector<TargetLineTruth> LoadTruthJson(const std::string& path) {
  std::ifstream in(path);
  if (!in) FileError(path, 0, "cannot open the truth file");
  std::vector<TargetLineTruth> lines;
  try {
    const nlohmann::json json = nlohmann::json::parse(in);
    auto line_of = [](const nlohmann::json& j) {
      return Normalized(j.at("rho").get<double>(), j.at("theta").get<double>());
    };
    auto point_of = [](const nlohmann::json& j) {
      return Point2d{j.at(0).get<double>(), j.at(1).get<double>()};
    };
    for (const nlohmann::json& line : json.at("lines")) {
      if (!line.at("visible").get<bool>()) continue;
      TargetLineTruth target;
      target.id = line.at("index").get<int>();
      target.image_line = line_of(line.at("distorted_fit"));
      target.ideal_line = line_of(line.at("ideal"));
      target.end_a = point_of(line.at("end_a"));
      target.end_b = point_of(line.at("end_b"));
      target.width_px = line.value("width_px", 0.0);
      lines.push_back(target);
    }
  } catch (const nlohmann::json::exception& error) {
    FileError(path, 0, std::string("malformed truth: ") + error.what());
  }
  return lines;
}

namespace {

// The oal-target method when the frames show a known four-line target: the config's `target:`
// section, else the target.yaml `oalservo render` writes next to its frames; it needs the
// camera (--camera) for the pose. None otherwise (a warning says why when a target is known).
std::unique_ptr<LineMethod> TargetMethod(const CompareOptions& options, AppConfig config,
                                         const std::optional<CameraFile>& camera,
                                         std::vector<std::string>* warnings) {
  std::string origin;
  if (!options.config_path.empty() && ConfigHasSection(options.config_path, "target")) {
    origin = options.config_path;
  } else if (const auto companion = CompanionFile({options.input}, "target.yaml")) {
    config.target = LoadConfig(*companion, AppConfig()).target;
    origin = *companion;
  } else {
    return nullptr;
  }
  if (config.target.lines.size() != 4) return nullptr;
  if (!camera) {
    warnings->push_back("the target of " + origin +
                        " is not tracked (oal-target): give the camera file (--camera) for "
                        "its pose");
    return nullptr;
  }
  return std::make_unique<OalTargetMethod>(config, camera->camera);
}

}  // namespace

namespace {

// The truth --truth names: a CSV's line rows by frame number, or a directory of frame JSON
// files; `source` says which ("csv", "json"; left empty without --truth).
struct GivenTruth {
  std::map<int, std::vector<TargetLineTruth>> csv;
  std::string json_dir;  ///< "" = next to the images
};

GivenTruth OpenGivenTruth(const CompareOptions& options, bool camera_given, std::string* source) {
  GivenTruth given;
  const bool truth_is_csv = !options.truth.empty() && fs::path(options.truth).extension() == ".csv";
  if (truth_is_csv) {
    if (camera_given) {
      throw std::invalid_argument(
          "--camera with a CSV truth: the CSV gives image-coordinate lines only, while --camera "
          "makes our lines undistorted; drop one of them");
    }
    given.csv = LoadTruthCsv(options.truth);
    if (given.csv.empty()) {
      throw std::runtime_error("truth " + options.truth +
                               " has no line row (frame,line,rho,theta): it matches no frame");
    }
    *source = "csv";
  } else if (!options.truth.empty()) {
    if (!fs::is_directory(options.truth)) {
      throw std::runtime_error("truth '" + options.truth +
                               "' is neither a .csv file nor a directory of frame JSON files");
    }
    given.json_dir = options.truth;
    *source = "json";
  }
  return given;
}

// A CSV truth that matches none of the input's frames is an error; one that misses some, a
// warning naming them.
void CheckCsvCoverage(const CompareOptions& options,
                      const std::map<int, std::vector<TargetLineTruth>>& csv,
                      const std::vector<int>& frames_seen, const std::vector<int>& without_truth,
                      std::vector<std::string>* warnings) {
  std::vector<int> truth_frames;
  for (const auto& [number, rows] : csv) truth_frames.push_back(number);
  const std::size_t without = without_truth.size();
  if (without == frames_seen.size()) {
    throw std::runtime_error("truth " + options.truth + " matches no frame of " + options.input +
                             ": its rows are for frames " + FrameRanges(truth_frames) +
                             ", the input's frames are " + FrameRanges(frames_seen) +
                             " (frame = the last number in the file name)");
  }
  if (without > 0) {
    warnings->push_back(std::to_string(without) + " of " + std::to_string(frames_seen.size()) +
                        " frames have no row in truth " + options.truth + " (frames " +
                        FrameRanges(without_truth) + "): scored as frames without target lines");
  }
}

// The figures (first, middle, and the frame worst for us: most lines missed, then the most
// spurious lines; fetched by a second pass over the input), compare.md and compare.json in
// --out, each written atomically, all committed together.
void WriteComparisonFiles(const CompareOptions& options,
                          const std::vector<std::unique_ptr<LineMethod>>& methods,
                          const std::vector<std::vector<TargetLineTruth>>& truth_per_frame,
                          const std::optional<CameraFile>& camera, CompareReport* out) {
  CompareReport& report = *out;
  const bool has_truth = report.truth_source != "none";
  std::vector<int> chosen{0, report.frames / 2};
  if (has_truth) {
    const MethodResult& us = report.methods[0];
    int worst = 0;
    for (int f = 1; f < report.frames; ++f) {
      if (us.missed_per_frame[static_cast<std::size_t>(f)] >
          us.missed_per_frame[static_cast<std::size_t>(worst)]) {
        worst = f;
      }
    }
    chosen.push_back(worst);
  } else {
    chosen.push_back(report.frames - 1);
  }
  std::sort(chosen.begin(), chosen.end());
  chosen.erase(std::unique(chosen.begin(), chosen.end()), chosen.end());
  if (static_cast<int>(chosen.size()) > options.figures)
    chosen.resize(static_cast<std::size_t>(options.figures));

  fs::create_directories(options.out_dir);
  const fs::path dir(options.out_dir);
  std::vector<std::unique_ptr<AtomicFile>> files;
  if (!chosen.empty()) {
    std::vector<bool> undistorted;
    for (const auto& method : methods) undistorted.push_back(method->Undistorted());
    std::unique_ptr<ImageSource> again = OpenImageSource(options.input);
    Frame frame;
    for (int f = 0; f <= chosen.back() && again->Next(&frame); ++f) {
      if (!std::binary_search(chosen.begin(), chosen.end(), f)) continue;
      const cv::Mat figure = Figure(frame.gray, f, report, truth_per_frame, undistorted, camera);
      std::vector<unsigned char> png;
      if (!cv::imencode(".png", figure, png)) {
        throw std::runtime_error("cannot encode " + (dir / FigureName(f)).string());
      }
      files.push_back(std::make_unique<AtomicFile>(dir / FigureName(f)));
      files.back()->stream().write(reinterpret_cast<const char*>(png.data()),
                                   static_cast<std::streamsize>(png.size()));
      report.figures.push_back((dir / FigureName(f)).string());
    }
  }
  files.push_back(std::make_unique<AtomicFile>(dir / "compare.md"));
  files.back()->stream() << CompareMarkdown(report);
  files.push_back(std::make_unique<AtomicFile>(dir / "compare.json"));
  files.back()->stream() << CompareJson(report).dump(2) << '\n';
  for (auto& file : files) file->Commit();
}

// The methods compared, ours first (without truth its lines are the targets of the
// trackers): the OAL detector and tracker, vpMeLine, OpenCV's detectors, the target tracker
// when the configuration has a target, and the caller's.
std::vector<std::unique_ptr<LineMethod>> ComparedMethods(
    const CompareOptions& options, const AppConfig& config, const std::optional<CameraFile>& camera,
    bool stripes, CompareReport* report, std::vector<std::unique_ptr<LineMethod>> extra_methods) {
  std::vector<std::unique_ptr<LineMethod>> methods;
  methods.push_back(std::make_unique<OalMethod>(config.detector, camera));
  methods.push_back(std::make_unique<OalTrackerMethod>(config.detector, camera));
  methods.push_back(std::make_unique<VpMeLineMethod>(options.me, stripes));
  using Kind = OpenCvMethod::Kind;
  for (Kind kind : {Kind::kHoughCanny, Kind::kHoughOtsu, Kind::kHoughP, Kind::kLsd, Kind::kFld}) {
    methods.push_back(std::make_unique<OpenCvMethod>(kind, stripes, config.detector.polarity,
                                                     report->max_stripe_width_px, config.detector));
  }
  if (auto target = TargetMethod(options, config, camera, &report->warnings)) {
    methods.push_back(std::move(target));
  }
  for (auto& extra : extra_methods) methods.push_back(std::move(extra));
  return methods;
}

}  // namespace

CompareReport RunComparison(const CompareOptions& options,
                            std::vector<std::unique_ptr<LineMethod>> extra_methods) {
  options.Check();
  CompareReport report;
  report.options = options;
  AppConfig config;
  if (!options.config_path.empty()) config = LoadConfig(options.config_path, config);
  config.detector.Check();
  std::optional<CameraFile> camera;
  if (!options.camera_path.empty()) camera = LoadCameraFile(options.camera_path);

  const GivenTruth given = OpenGivenTruth(options, camera.has_value(), &report.truth_source);
  const std::map<int, std::vector<TargetLineTruth>>& csv = given.csv;
  const std::string& json_dir = given.json_dir;

  // Unexpected files skipped in a directory, and files after a pattern's gap, are warned
  // about (the truth JSON and camera.xml are expected there: no warning).
  std::unique_ptr<ImageSource> source = OpenImageSource(options.input, &report.warnings);
  Frame frame;
  if (!source->Next(&frame)) throw std::runtime_error(source->Name() + " holds no frame");
  report.width = frame.gray.cols;
  report.height = frame.gray.rows;
  if (camera) {
    if (auto warning =
            CameraSizeMismatch(*camera, frame.gray.cols, frame.gray.rows, frame.source)) {
      report.warnings.push_back(*warning);
    }
  }

  auto json_path = [&](const Frame& f) {
    const fs::path image(f.source);
    return json_dir.empty() ? fs::path(image).replace_extension(".json")
                            : fs::path(json_dir) / (image.stem().string() + ".json");
  };
  if (report.truth_source.empty()) {
    report.truth_source = fs::is_regular_file(json_path(frame)) ? "json" : "none";
    if (report.truth_source == "none") {
      report.warnings.push_back("no truth (" + json_path(frame).string() +
                                " does not exist): only timing is measured");
    }
  }
  const bool has_truth = report.truth_source != "none";
  auto truth_of = [&](const Frame& f, int index) {
    if (report.truth_source == "json") return LoadTruthJson(json_path(f).string());
    std::vector<TargetLineTruth> lines;
    if (report.truth_source == "csv") {
      const auto it = csv.find(FrameNumber(f.source, index));
      if (it != csv.end()) {
        for (TargetLineTruth target : it->second) {
          if (ClipChord(&target, f.gray.cols, f.gray.rows)) lines.push_back(target);
        }
      }
    }
    return lines;
  };

  std::vector<TargetLineTruth> truth = truth_of(frame, 0);
  report.target_kind = options.target_kind;
  if (report.target_kind == TargetKind::kAuto) {
    report.target_kind =
        config.detector.polarity == Polarity::kEdges ? TargetKind::kEdges : TargetKind::kStripes;
  }
  const bool stripes = report.target_kind == TargetKind::kStripes;
  report.max_stripe_width_px = options.max_stripe_width_px;
  if (report.max_stripe_width_px == 0.0) {
    double widest = 0.0;
    for (const TargetLineTruth& target : truth) widest = std::max(widest, target.width_px);
    report.max_stripe_width_px = widest > 0.0 ? 1.5 * widest + 2.0 : 30.0;
  }

  std::vector<std::unique_ptr<LineMethod>> methods =
      ComparedMethods(options, config, camera, stripes, &report, std::move(extra_methods));
  const OalMethod* ours = static_cast<const OalMethod*>(methods.front().get());
  for (const auto& method : methods) {
    MethodResult result;
    result.name = method->Name();
    result.reference = !has_truth                     ? "none"
                       : report.truth_source == "csv" ? "csv"
                       : method->Undistorted()        ? "ideal"
                                                      : "distorted_fit";
    report.methods.push_back(std::move(result));
  }

  Scorer scorer{options.max_angle_deg, options.max_offset_px, std::nullopt};
  if (camera) scorer.undistorter.emplace(camera->camera);
  const std::size_t untruthed_targets =
      options.lines > 0 ? static_cast<std::size_t>(options.lines) : 4;
  std::vector<std::vector<TargetLineTruth>> truth_per_frame;
  std::vector<int> csv_frames_seen, csv_frames_without_truth;  // frame numbers (CSV truth)
  std::vector<MethodFailure> method_failures(methods.size());
  vpImage<unsigned char> image;
  std::vector<LineParams> lines;
  int index = 0;
  do {
    if (index > 0) truth = truth_of(frame, index);
    if (report.truth_source == "csv") {
      const int number = FrameNumber(frame.source, index);
      csv_frames_seen.push_back(number);
      if (csv.count(number) == 0) csv_frames_without_truth.push_back(number);
    }
    CopyInto(frame.gray, &image);
    std::vector<TargetLineTruth> targets = truth;
    for (std::size_t m = 0; m < methods.size(); ++m) {
      LineMethod& method = *methods[m];
      MethodResult& result = report.methods[m];
      if (index == 0 && m > 0) method.Start(image, targets, has_truth);
      const auto start = std::chrono::steady_clock::now();
      try {
        method.Process(image, &lines);
      } catch (const cv::Exception& error) {  // e.g. an image too small for the method
        lines.clear();
        method_failures[m].Add(index, frame, error);
      }
      const auto stop = std::chrono::steady_clock::now();
      const double time_us = std::chrono::duration<double, std::micro>(stop - start).count();
      if (m == 0 && !has_truth) {
        targets = TargetsFromDetections(ours->last(), untruthed_targets, ours->Undistorted(),
                                        camera, frame.gray.cols, frame.gray.rows);
      }
      const std::size_t k =
          options.lines > 0 ? static_cast<std::size_t>(options.lines) : truth.size() + 2;
      if (lines.size() > k) lines.resize(k);
      result.time_us.push_back(time_us);
      const std::size_t per = has_truth ? truth.size() : targets.size();
      result.time_us_per_line.push_back(time_us /
                                        static_cast<double>(std::max<std::size_t>(1, per)));
      if (has_truth) {
        scorer.Score(lines, truth, method.Undistorted(), &result);
      } else {
        result.spurious_lines += static_cast<int>(lines.size());  // lines, unscored
      }
      result.lines.push_back(lines);
      ++result.frames;
    }
    for (std::size_t m = 1; m < methods.size(); ++m) {
      methods[m]->AfterFrame(image, targets, has_truth);
    }
    truth_per_frame.push_back(has_truth ? truth : std::vector<TargetLineTruth>());
    ++index;
  } while ((options.max_frames == 0 || index < options.max_frames) && source->Next(&frame));
  report.frames = index;
  for (std::size_t m = 0; m < methods.size(); ++m) {
    report.methods[m].failures = methods[m]->failures();
    report.methods[m].reinitialisations = methods[m]->reinitialisations();
    if (method_failures[m].frames > 0) {
      report.warnings.push_back(method_failures[m].Warning(report.methods[m].name));
    }
  }
  if (report.truth_source == "csv") {
    CheckCsvCoverage(options, csv, csv_frames_seen, csv_frames_without_truth, &report.warnings);
  }
  if (options.out_dir.empty()) return report;

  WriteComparisonFiles(options, methods, truth_per_frame, camera, &report);
  return report;
}

std::string CompareMarkdown(const CompareReport& report) {
  std::ostringstream out;
  const bool truth = report.truth_source != "none";
  out << "`oalservo compare` on " << report.options.input << ": " << report.frames << " frames "
      << report.width << "x" << report.height << ", truth: " << report.truth_source
      << ", target lines: " << ToString(report.target_kind);
  if (truth) {
    out << ", a line is found within " << report.options.max_angle_deg << "° and "
        << report.options.max_offset_px << " px, scored lines per frame: "
        << (report.options.lines > 0 ? std::to_string(report.options.lines) : "truth + 2");
  }
  out << "\n\n";
  if (truth) {
    out << "| method | reference | frames all found | lines found | angle error mean / p95 (°) "
           "| offset error mean / p95 (px) | spurious / frame | time / frame, median (µs) | "
           "time / line, median (µs) | failures / re-inits |\n"
        << "|---|---|---|---|---|---|---|---|---|---|\n";
  } else {
    out << "| method | lines / frame | time / frame, median (µs) | time / line, median (µs) | "
           "failures / re-inits |\n|---|---|---|---|---|\n";
  }
  for (const MethodResult& m : report.methods) {
    const std::string tracker = m.reinitialisations < 0 ? "—"
                                                        : std::to_string(m.failures) + " / " +
                                                              std::to_string(m.reinitialisations);
    const double frames = std::max(1, m.frames);
    if (truth) {
      out << "| " << m.name << " | " << m.reference << " | " << m.frames_all_found << " / "
          << m.frames << " | " << m.found_lines << " / " << m.truth_lines << " | "
          << Fixed(Mean(m.angle_error_deg), 3) << " / "
          << Fixed(Quantile(m.angle_error_deg, 0.95), 3) << " | "
          << Fixed(Mean(m.offset_error_px), 2) << " / "
          << Fixed(Quantile(m.offset_error_px, 0.95), 2) << " | "
          << Fixed(m.spurious_lines / frames, 2) << " | " << Fixed(Quantile(m.time_us, 0.5), 0)
          << " | " << Fixed(Quantile(m.time_us_per_line, 0.5), 0) << " | " << tracker << " |\n";
    } else {
      out << "| " << m.name << " | " << Fixed(m.spurious_lines / frames, 2) << " | "
          << Fixed(Quantile(m.time_us, 0.5), 0) << " | "
          << Fixed(Quantile(m.time_us_per_line, 0.5), 0) << " | " << tracker << " |\n";
    }
  }
  return out.str();
}

Json CompareJson(const CompareReport& report) {
  const bool truth = report.truth_source != "none";
  Json methods = Json::array();
  for (const MethodResult& m : report.methods) {
    Json method{{"name", m.name}, {"reference", m.reference}, {"frames", m.frames}};
    if (truth) {
      method["frames_all_found"] = m.frames_all_found;
      method["truth_lines"] = m.truth_lines;
      method["found_lines"] = m.found_lines;
      method["angle_error_deg"] = {{"mean", Mean(m.angle_error_deg)},
                                   {"p95", Quantile(m.angle_error_deg, 0.95)}};
      method["offset_error_px"] = {{"mean", Mean(m.offset_error_px)},
                                   {"p95", Quantile(m.offset_error_px, 0.95)}};
      method["spurious_per_frame"] =
          m.frames ? static_cast<double>(m.spurious_lines) / m.frames : 0.0;
      method["missed_frames"] = m.missed_frames;
    } else {
      method["lines_per_frame"] = m.frames ? static_cast<double>(m.spurious_lines) / m.frames : 0.0;
    }
    method["time_us_per_frame_median"] = Quantile(m.time_us, 0.5);
    method["time_us_per_line_median"] = Quantile(m.time_us_per_line, 0.5);
    if (m.reinitialisations >= 0) {
      method["failures"] = m.failures;
      method["reinitialisations"] = m.reinitialisations;
    }
    methods.push_back(std::move(method));
  }
  const CompareOptions& o = report.options;
  return Json{{"input", o.input},
              {"truth", report.truth_source},
              {"frames", report.frames},
              {"width", report.width},
              {"height", report.height},
              {"target_kind", ToString(report.target_kind)},
              {"max_angle_deg", o.max_angle_deg},
              {"max_offset_px", o.max_offset_px},
              {"lines_scored", o.lines > 0 ? Json(o.lines) : Json("truth + 2")},
              {"max_stripe_width_px", report.max_stripe_width_px},
              {"vpme",
               {{"range_px", o.me.range_px},
                {"threshold", o.me.threshold},
                {"sample_step_px", o.me.sample_step_px},
                {"drift_angle_deg", o.me.drift_angle_deg},
                {"drift_offset_px", o.me.drift_offset_px}}},
              {"methods", std::move(methods)},
              {"figures", report.figures},
              {"warnings", report.warnings}};
}

}  // namespace oal
