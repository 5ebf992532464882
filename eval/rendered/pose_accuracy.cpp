#include "eval/rendered/pose_accuracy.h"

#include <visp3/core/vpRzyxVector.h>
#include <visp3/core/vpThetaUVector.h>

#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

#include "base/clock.h"
#include "base/pose_distance.h"
#include "detector/lens.h"
#include "loop/lens_estimate.h"

namespace oal {
namespace {

// Roll of cMo in the convention of PoseResult::roll_deg: cRo = Rz(roll) Ry(yaw) Rx(pitch).
double RollDeg(const vpHomogeneousMatrix& cMo) {
  vpRotationMatrix cRo;
  cMo.extract(cRo);
  return vpMath::deg(vpRzyxVector(cRo)[0]);
}

// Whether every visible target line has a line of `lines` within the bounds: its angle to the
// projected centre line, and the larger distance of the visible chord's (undistorted) ends.
bool AllLinesFound(const std::vector<DetectedLine>& lines, const RenderedFrame& frame,
                   const PointUndistorter& undistorter, bool undistorted,
                   const PoseAccuracyOptions& options) {
  for (const TruthLine& truth : frame.truth) {
    if (!truth.visible) continue;
    const LineParams& reference = undistorted ? truth.ideal : truth.distorted_fit;
    const Point2d a = undistorted ? undistorter.Undistort(truth.end_a) : truth.end_a;
    const Point2d b = undistorted ? undistorter.Undistort(truth.end_b) : truth.end_b;
    bool found = false;
    for (const DetectedLine& line : lines) {
      const double angle = vpMath::deg(AngleBetween(line.line, reference));
      const double offset = std::max(std::fabs(line.line.SignedDistance(a.u, a.v)),
                                     std::fabs(line.line.SignedDistance(b.u, b.v)));
      if (angle <= options.line_angle_deg && offset <= options.line_offset_px) {
        found = true;
        break;
      }
    }
    if (!found) return false;
  }
  return true;
}

}  // namespace

int PoseAccuracyReport::posed() const {
  const auto ok = status_counts.find(ToString(TargetStatus::kOk));
  return ok == status_counts.end() ? 0 : ok->second;
}

PoseSampling PoseAccuracyOptions::BoardSampling() {
  PoseSampling sampling;
  sampling.min_distance_m = 0.3;
  sampling.max_distance_m = 1.0;
  sampling.max_tilt_deg = 40.0;
  sampling.min_visible_length_px = 150.0;
  return sampling;
}

void PoseAccuracyOptions::Check() const {
  RenderedFrameOptions::Check();
  detector.Check();
  tracking.Check();
  sampling.Check();
  PoseOptions check = pose;
  check.camera = MakeRenderOptions(*this).camera;
  check.Check();
  IdentifyTargetLines({}, target, check);  // throws unless the target is a '#'
  RequireOption(estimate_frames >= 1 && estimate_frames <= 100,
                "PoseAccuracyOptions::estimate_frames", estimate_frames,
                "1 <= estimate_frames <= 100");
  if (given_camera) CheckPerspectiveCamera(*given_camera, "PoseAccuracyOptions::given_camera");
  RequireOption(!given_camera || !estimate_distortion, "PoseAccuracyOptions::estimate_distortion",
                estimate_distortion, "false with a given camera");
  RequireOption(marker == SheetMarker::kOal || !estimate_distortion,
                "PoseAccuracyOptions::estimate_distortion", estimate_distortion,
                "false with a marker (the lens is told from our target's stripes)");
}

namespace {

// The lens is told on poses of its own, apart from the evaluated ones.
constexpr std::uint64_t kLensSeedOffset = 0x9e3779b97f4a7c15ULL;

// The camera with the lens the stripes tell, from frames tracked by a pinhole camera; the
// pinhole camera itself, with report->estimate_failed saying why, when they cannot tell it.
Lens EstimatedCamera(const EvaluationScenes& scenes, const PoseAccuracyOptions& options,
                     PoseAccuracyReport* report) {
  const Lens lens = scenes.For(0).options().camera;
  Lens pinhole = Lens::Pinhole(lens.px(), lens.py(), lens.u0(), lens.v0());
  TargetPoseTracker tracker(options.target, pinhole, options.detector, options.pose,
                            options.tracking);
  std::uint64_t state = options.seed + kLensSeedOffset;
  int frame = 0;
  RenderedFrame rendered;
  const ToldLens told = TellLensFromStripes(
      tracker, pinhole,
      [&](GrayImageView* view) {
        const SceneRenderer& renderer = scenes.For(frame);
        rendered =
            renderer.Render(SamplePose(renderer, options.sampling, &state),
                            state + static_cast<std::uint64_t>(frame), scenes.EffectsFor(frame));
        ++frame;
        *view = ViewOf(rendered.image);
        return true;
      },
      options.estimate_frames);
  report->estimated_kdu = std::numeric_limits<double>::quiet_NaN();
  if (!told.lens) {
    report->estimate_failed = told.why;
    return pinhole;
  }
  report->estimated_kdu = told.lens->kdu;
  report->estimated_kdu_sd = told.lens->kdu_sd;
  return WithLens(pinhole, *told.lens);
}

// A found pose's errors against the truth, added to `report`.
struct PoseErrors {
  double translation_pct = 0.0, rotation_deg = 0.0;
  bool wrong = false;
};
PoseErrors RecordPose(const vpHomogeneousMatrix& cMo_true, const vpHomogeneousMatrix& cMo,
                      int frame, const PoseAccuracyOptions& options, PoseAccuracyReport* report) {
  const PoseDistance error = Distance(cMo_true, cMo);
  PoseErrors errors;
  errors.translation_pct =
      100.0 * error.translation_m / cMo_true.getTranslationVector().frobeniusNorm();
  errors.rotation_deg = vpMath::deg(error.rotation_rad);
  report->translation_error_pct.push_back(errors.translation_pct);
  report->rotation_error_deg.push_back(errors.rotation_deg);
  double roll_error = std::fabs(RollDeg(cMo) - RollDeg(cMo_true));
  roll_error = std::fmod(roll_error, 360.0);
  roll_error = std::min(roll_error, 360.0 - roll_error);
  report->roll_error_deg.push_back(roll_error);
  report->roll_flips += roll_error > 45.0;
  errors.wrong = errors.translation_pct > options.wrong_translation_pct ||
                 errors.rotation_deg > options.wrong_rotation_deg;
  if (errors.wrong) report->wrong_frames.push_back(frame);
  return errors;
}

// Whether every corner of `outline` (plane points) is in front of the camera and inside the
// distorted image of `render`.
bool OutlineInView(const RenderOptions& render, const vpHomogeneousMatrix& cMo,
                   const std::array<std::array<double, 2>, 4>& outline) {
  for (const auto& corner : outline) {
    const double z = cMo[2][0] * corner[0] + cMo[2][1] * corner[1] + cMo[2][3];
    if (!(z > 0.0)) return false;
    const double x = (cMo[0][0] * corner[0] + cMo[0][1] * corner[1] + cMo[0][3]) / z;
    const double y = (cMo[1][0] * corner[0] + cMo[1][1] * corner[1] + cMo[1][3]) / z;
    const Point2d pixel = render.camera.Pixel(x, y);
    if (!(pixel.u >= 0.0 && pixel.u <= render.width - 1 && pixel.v >= 0.0 &&
          pixel.v <= render.height - 1)) {
      return false;
    }
  }
  return true;
}

// The marker's frames: the poses, effects and noise of our target's frames (the same calls in
// the same order), the marker printed on the board instead of the stripes.
PoseAccuracyReport EvaluateMarkerPoseAccuracy(const PoseAccuracyOptions& options,
                                              const std::function<void(int, int)>& progress) {
  const EvaluationScenes scenes(options.target, options);
  const RenderOptions& render = scenes.For(0).options();
  const std::unique_ptr<MarkerMethod> method =
      MakeMarkerMethod(options.marker, options.target, options.given_camera.value_or(render.camera),
                       render.width, render.height);
  const MarkerPrint& print = method->Print();
  const EvaluationScenes printed(MarkerSheet(options.target, *method), options, print.picture);

  PoseAccuracyReport report;
  report.options = options;
  report.marker_description = print.description;
  for (const MarkerStatus status :
       {MarkerStatus::kOk, MarkerStatus::kNotFound, MarkerStatus::kNoPose}) {
    report.status_counts[ToString(status)] = 0;
  }
  std::uint64_t state = options.seed;
  const int end = options.first_frame + options.frames;
  for (int frame = 0; frame < end; ++frame) {
    const vpHomogeneousMatrix cMo_true = SamplePose(scenes.For(frame), options.sampling, &state);
    if (frame < options.first_frame) continue;
    const std::uint64_t noise_seed = options.seed * 7919ULL + frame;
    const FrameEffects effects = scenes.EffectsFor(frame);
    const SceneRenderer& renderer = printed.For(frame);
    const RenderedFrame rendered = renderer.Render(cMo_true, noise_seed, effects);
    const bool in_view = OutlineInView(renderer.options(), cMo_true, print.outline_m);

    const auto start = std::chrono::steady_clock::now();
    const MarkerPose found = method->Find(rendered.image);
    report.total_time_us.push_back(MicrosecondsSince(start));
    report.detect_time_us.push_back(found.detect_us);
    report.pose_time_us.push_back(found.pose_us);

    ++report.frames;
    ++report.status_counts[ToString(found.status)];
    report.marker_in_view += in_view;
    if (found.status != MarkerStatus::kOk) {
      report.failed_frames.push_back(frame);
    } else {
      report.posed_in_view += in_view;
      RecordPose(cMo_true, found.cMo, frame, options, &report);
    }
    if (progress) progress(frame + 1 - options.first_frame, options.frames);
  }
  return report;
}

}  // namespace

PoseAccuracyReport EvaluatePoseAccuracy(
    const PoseAccuracyOptions& options, const std::function<void(int, int)>& progress,
    const std::function<void(const PoseAccuracyMiss&)>& on_miss) {
  options.Check();
  if (options.marker != SheetMarker::kOal) return EvaluateMarkerPoseAccuracy(options, progress);
  const EvaluationScenes scenes(options.target, options);
  PoseAccuracyReport report;
  const Lens camera = options.estimate_distortion
                          ? EstimatedCamera(scenes, options, &report)
                          : options.given_camera.value_or(scenes.For(0).options().camera);
  TargetPoseTracker tracker(options.target, camera, options.detector, options.pose,
                            options.tracking);
  const PointUndistorter undistorter(camera);
  const bool undistorted = tracker.detector().Undistorts();

  report.options = options;
  // Every status, so that the report's keys do not depend on what happened.
  for (const TargetStatus status : {TargetStatus::kOk, TargetStatus::kNotFound,
                                    TargetStatus::kModelMismatch, TargetStatus::kJump}) {
    report.status_counts[ToString(status)] = 0;
  }
  std::uint64_t state = options.seed;
  const int end = options.first_frame + options.frames;
  for (int frame = 0; frame < end; ++frame) {
    const SceneRenderer& renderer = scenes.For(frame);
    const vpHomogeneousMatrix cMo_true = SamplePose(renderer, options.sampling, &state);
    if (frame < options.first_frame) continue;
    const std::uint64_t noise_seed = options.seed * 7919ULL + frame;
    const FrameEffects effects = scenes.EffectsFor(frame);
    const RenderedFrame rendered = renderer.Render(cMo_true, noise_seed, effects);

    tracker.Reset();  // each frame on its own
    const auto start = std::chrono::steady_clock::now();
    const TargetFrame& result = tracker.Track(ViewOf(rendered.image));
    report.total_time_us.push_back(MicrosecondsSince(start));
    report.find_time_us.push_back(result.find_us);
    report.detect_time_us.push_back(result.detect_us);
    report.pose_time_us.push_back(result.pose_us);

    ++report.frames;
    ++report.status_counts[ToString(result.status)];
    report.lines_found +=
        AllLinesFound(tracker.lines(), rendered, undistorter, undistorted, options);
    auto missed = [&](bool wrong, double t_pct, double r_deg) {
      if (!on_miss) return;
      on_miss(PoseAccuracyMiss{frame, rendered, renderer.options(), noise_seed, effects, result,
                               wrong, t_pct, r_deg});
    };
    if (result.status != TargetStatus::kOk) {
      ++report.pose_status_counts[ToString(result.pose.status)];
      report.failed_frames.push_back(frame);
      missed(false, 0.0, 0.0);
    } else {
      ++report.source_counts[ToString(result.source)];
      const PoseErrors errors = RecordPose(cMo_true, result.pose.cMo, frame, options, &report);
      if (errors.wrong) missed(true, errors.translation_pct, errors.rotation_deg);
    }
    if (progress) progress(frame + 1 - options.first_frame, options.frames);
  }
  return report;
}

}  // namespace oal
