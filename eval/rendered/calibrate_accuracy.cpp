#include "eval/rendered/calibrate_accuracy.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "base/check.h"
#include "calibration/sheet_view_finder.h"
#include "detector/lens.h"

namespace oal {
namespace {

// Streams of Uniform01 for the camera's draws.
enum Draw : std::uint64_t { kFocal = 11, kAspect, kCentreU, kCentreV, kLens };

Lens DrawCamera(const CalibrateAccuracyOptions& o, int camera) {
  if (o.lens) return *o.lens;
  const auto draw = [&](double lo, double hi, Draw stream) {
    return lo + (hi - lo) * Uniform01(o.seed, camera, stream);
  };
  const double px = draw(o.min_focal_px, o.max_focal_px, kFocal);
  const double py = px * draw(0.99, 1.01, kAspect);
  const double u0 =
      0.5 * (o.width - 1) + draw(-o.max_centre_offset_px, o.max_centre_offset_px, kCentreU);
  const double v0 =
      0.5 * (o.height - 1) + draw(-o.max_centre_offset_px, o.max_centre_offset_px, kCentreV);
  return Lens::WithKdu(px, py, u0, v0, draw(o.min_kdu, o.max_kdu, kLens), o.width, o.height);
}

double TiltDeg(const vpHomogeneousMatrix& cMo) {
  return std::acos(std::min(1.0, std::fabs(cMo[2][2]))) * 180.0 / M_PI;
}

}  // namespace

void CalibrateAccuracyOptions::Check() const {
  RenderedFrameOptions::Check();
  target.Check();
  sampling.Check();
  RequireOption(cameras >= 1 && cameras <= 1000, "CalibrateAccuracyOptions::cameras", cameras,
                "1 <= cameras <= 1000");
  RequireOption(frames >= 3, "CalibrateAccuracyOptions::frames", frames, "frames >= 3");
  RequireOption(min_focal_px > 0.0 && min_focal_px <= max_focal_px,
                "CalibrateAccuracyOptions::min_focal_px", min_focal_px,
                "0 < min_focal_px <= max_focal_px");
  RequireOption(max_centre_offset_px >= 0.0 && max_centre_offset_px <= 0.25 * width,
                "CalibrateAccuracyOptions::max_centre_offset_px", max_centre_offset_px,
                "0 <= max_centre_offset_px <= a quarter of the width");
  if (lens) CheckInvertibleOver(*lens, width, height, "CalibrateAccuracyOptions::lens");
  RequireOption(min_kdu > -1.0 && min_kdu <= max_kdu && max_kdu < 1.0,
                "CalibrateAccuracyOptions::min_kdu", min_kdu, "-1 < min_kdu <= max_kdu < 1");
  RequireOption(min_tilt_deg >= 0.0 && min_tilt_deg < sampling.max_tilt_deg,
                "CalibrateAccuracyOptions::min_tilt_deg", min_tilt_deg,
                "0 <= min_tilt_deg < sampling.max_tilt_deg");
}

double CameraCalibrationTrial::px_error_pct() const {
  return 100.0 * std::fabs(found.px() - truth.px()) / truth.px();
}
double CameraCalibrationTrial::py_error_pct() const {
  return 100.0 * std::fabs(found.py() - truth.py()) / truth.py();
}
double CameraCalibrationTrial::u0_error_px() const {
  return std::fabs(found.u0() - truth.u0());
}
double CameraCalibrationTrial::v0_error_px() const {
  return std::fabs(found.v0() - truth.v0());
}

std::vector<CameraCalibrationTrial> EvaluateCalibration(
    const CalibrateAccuracyOptions& options,
    const std::function<void(int done, int total)>& progress) {
  options.Check();
  std::vector<CameraCalibrationTrial> trials;
  const int total = options.cameras * options.frames;
  for (int c = 0; c < options.cameras; ++c) {
    CameraCalibrationTrial& trial = trials.emplace_back();
    trial.truth = DrawCamera(options, c);
    RenderedFrameOptions render = options;
    render.camera = trial.truth;
    render.seed = options.seed * 1000003ULL + static_cast<std::uint64_t>(c);
    const EvaluationScenes scenes(options.target, render);
    SheetViewFinder finder(options.target, options.width, options.height, options.detector,
                           options.pose, options.tracking);
    std::vector<CalibrationView> views;
    std::uint64_t state = render.seed;
    for (int v = 0; v < options.frames; ++v) {
      const SceneRenderer& renderer = scenes.For(v);
      vpHomogeneousMatrix cMo = SamplePose(renderer, options.sampling, &state);
      for (int draw = 0; draw < 100 && TiltDeg(cMo) < options.min_tilt_deg; ++draw) {
        cMo = SamplePose(renderer, options.sampling, &state);
      }
      const RenderedFrame frame = renderer.Render(
          cMo, render.seed * 7919ULL + static_cast<std::uint64_t>(v), scenes.EffectsFor(v));
      views.push_back(finder.Find(ViewOf(frame.image),
                                  "camera " + std::to_string(c) + " view " + std::to_string(v)));
      if (progress) progress(c * options.frames + v + 1, total);
    }
    CalibrationOptions calibration;
    calibration.width = options.width;
    calibration.height = options.height;
    trial.views = options.frames;
    try {
      const CalibrationResult result = Calibrate(views, calibration);
      trial.found = result.camera;
      trial.lens_error_px = WorstIdealPixelDifference(
          trial.found, trial.truth, options.width, options.height,
          kLensJudgedFraction * 0.5 * std::hypot(options.width, options.height));
      trial.rms_px = result.rms_px;
      trial.used = static_cast<int>(std::count_if(result.views.begin(), result.views.end(),
                                                  [](const auto& view) { return view.used; }));
    } catch (const std::runtime_error& error) {
      trial.failed = error.what();
    }
  }
  return trials;
}

}  // namespace oal
