#include "eval/lines/vp_me_line_method.h"

#include <visp3/me/vpMe.h>
#include <visp3/me/vpMeLine.h>

#include <cmath>
#include <string>
#include <vector>

#include "base/angles.h"
#include "base/check.h"

namespace oal {
namespace {

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
          const double cost = AngleBetween(targets[i].image_line, track.line) * kDegPerRad / 5.0 +
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

}  // namespace

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

std::unique_ptr<LineMethod> MakeVpMeLineMethod(const VpMeLineOptions& options, bool stripes) {
  return std::make_unique<VpMeLineMethod>(options, stripes);
}

}  // namespace oal
