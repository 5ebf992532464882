#include "app/pose_accuracy.h"

#include <visp3/core/vpRzyxVector.h>
#include <visp3/core/vpThetaUVector.h>

#include <chrono>
#include <cmath>
#include <stdexcept>

#include "detector/detector.h"
#include "servo/pose.h"

namespace oal {
namespace {

double MicrosecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start)
      .count();
}

// Roll of cMo in the convention of PoseResult::roll_deg: cRo = Rz(roll) Ry(yaw) Rx(pitch).
double RollDeg(const vpHomogeneousMatrix& cMo) {
  vpRotationMatrix cRo;
  cMo.extract(cRo);
  return vpMath::deg(vpRzyxVector(cRo)[0]);
}

// options.pose with what the evaluation sets: the rendered camera, the detector's
// undistortion and the image size.
PoseOptions PoseOptionsFor(const PoseAccuracyOptions& options, const RenderOptions& render,
                           bool lines_undistorted) {
  PoseOptions pose = options.pose;
  pose.camera = render.camera;
  pose.lines_undistorted = lines_undistorted;
  pose.image_width = options.width;
  pose.image_height = options.height;
  return pose;
}

}  // namespace

void PoseAccuracyOptions::Check() const {
  RenderedFrameOptions::Check();
  detector.Check();
  PoseOptionsFor(*this, MakeRenderOptions(*this), true).Check();
}

PoseAccuracyReport EvaluatePoseAccuracy(const PoseAccuracyOptions& options,
                                        const std::function<void(int, int)>& progress) {
  options.Check();
  const RenderOptions render = MakeRenderOptions(options);
  const SceneRenderer renderer(FourLineTarget(), render);

  OalDetector detector(options.detector, render.camera);
  const PoseOptions pose_options = PoseOptionsFor(options, render, detector.Undistorts());

  PoseAccuracyReport report;
  report.options = options;
  std::uint64_t state = options.seed;
  for (int frame = 0; frame < options.frames; ++frame) {
    const vpHomogeneousMatrix cMo_true = SamplePose(renderer, options.sampling, &state);
    const RenderedFrame rendered = renderer.Render(cMo_true, options.seed * 7919ULL + frame);

    auto start = std::chrono::steady_clock::now();
    const std::vector<DetectedLine>& lines = detector.Detect(rendered.image);
    report.detect_time_us.push_back(MicrosecondsSince(start));
    start = std::chrono::steady_clock::now();
    const PoseResult pose = EstimatePose(lines, renderer.target(), pose_options);
    report.pose_time_us.push_back(MicrosecondsSince(start));

    ++report.frames;
    ++report.status_counts[static_cast<std::size_t>(pose.status)];
    if (pose.status != PoseStatus::kOk) {
      report.failed_frames.push_back(frame);
    } else {
      const vpTranslationVector error_t =
          pose.cMo.getTranslationVector() - cMo_true.getTranslationVector();
      report.translation_error_pct.push_back(100.0 * error_t.frobeniusNorm() /
                                             cMo_true.getTranslationVector().frobeniusNorm());
      const vpThetaUVector error_r((pose.cMo * cMo_true.inverse()).getRotationMatrix());
      report.rotation_error_deg.push_back(vpMath::deg(error_r.getTheta()));
      double roll_error = std::fabs(RollDeg(pose.cMo) - RollDeg(cMo_true));
      roll_error = std::fmod(roll_error, 360.0);
      roll_error = std::min(roll_error, 360.0 - roll_error);
      report.roll_error_deg.push_back(roll_error);
      report.roll_flips += roll_error > 45.0;
    }
    if (progress) progress(frame + 1, options.frames);
  }
  return report;
}

}  // namespace oal
