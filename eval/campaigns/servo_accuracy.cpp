#include "eval/campaigns/servo_accuracy.h"

#include <visp3/core/vpMath.h>

#include <stdexcept>

#include "base/check.h"
#include "scene/bench_scene.h"  // IsSheet
#include "scene/scene.h"

namespace oal {

int ServoAccuracyLaw::converged() const {
  int count = 0;
  for (const ServoAccuracyRun& run : runs) count += run.status == ServoRunStatus::kConverged;
  return count;
}

void ServoAccuracyOptions::Check() const {
  RequireOption(starts >= 1 && starts <= 1000000, "ServoAccuracyOptions::starts", starts,
                "1 <= starts <= 1000000");
  RequireOption(min_distance_m > 0.0, "ServoAccuracyOptions::min_distance_m", min_distance_m,
                "min_distance_m > 0");
  RequireOption(max_distance_m >= min_distance_m, "ServoAccuracyOptions::max_distance_m",
                max_distance_m, "max_distance_m >= min_distance_m");
  RequireOption(max_off_deg >= 0.0 && max_off_deg <= 80.0, "ServoAccuracyOptions::max_off_deg",
                max_off_deg, "0 <= max_off_deg <= 80");
  RequireOption(max_iterations >= 0, "ServoAccuracyOptions::max_iterations", max_iterations,
                "max_iterations >= 0");
  RequireOption(!modes.empty(), "ServoAccuracyOptions::modes", "none", "at least one law");
}

std::vector<vpHomogeneousMatrix> SampleServoStarts(const ServoStartScene& scene,
                                                   const ServoAccuracyOptions& options) {
  options.Check();
  RenderOptions render;
  render.width = scene.width;
  render.height = scene.height;
  render.camera = scene.camera;
  const SceneRenderer renderer(scene.target, render);
  PoseSampling sampling;
  sampling.min_distance_m = options.min_distance_m;
  sampling.max_distance_m = options.max_distance_m;
  sampling.max_tilt_deg = options.max_off_deg;
  sampling.max_offset_m = 0.05;
  sampling.any_roll = false;  // roll within ±max_off_deg of the goal's
  sampling.min_visible_length_px = 0.15 * scene.width;
  // A sheet is found by its middle cell: every start sees its four crossings.
  sampling.crossings_in_view = IsSheet(scene.target);
  std::uint64_t state = options.seed;
  std::vector<vpHomogeneousMatrix> starts;
  for (int i = 0; i < options.starts; ++i) {
    const vpHomogeneousMatrix cMo = SamplePose(renderer, sampling, &state);
    starts.push_back(scene.wMo * cMo.inverse());  // wMc = wMo · oMc
  }
  return starts;
}

ServoAccuracyReport EvaluateServoAccuracy(const ServoStartScene& scene,
                                          const ServoAccuracyOptions& options,
                                          const ServoRunFrom& run_from,
                                          const std::function<void(int, int)>& progress) {
  const std::vector<vpHomogeneousMatrix> starts = SampleServoStarts(scene, options);
  ServoAccuracyReport report;
  report.options = options;
  const int total = static_cast<int>(starts.size() * options.modes.size());
  int done = 0;
  for (const ServoMode mode : options.modes) {
    ServoAccuracyLaw law;
    law.mode = mode;
    for (std::size_t i = 0; i < starts.size(); ++i) {
      const AuditedServoRun audited =
          run_from(starts[i], mode, options.max_iterations, static_cast<int>(i));
      const ServoRunReport& result = audited.report;
      ServoAccuracyRun run;
      run.start = static_cast<int>(i);
      run.start_wMc = starts[i];
      run.status = result.status;
      run.message = result.message;
      run.moves = result.moves;
      run.unconfirmed_motions = audited.unconfirmed_motions;
      if (!result.iterations.empty()) {
        const ServoIteration& first = result.iterations.front();
        const ServoIteration& last = result.iterations.back();
        run.start_distance_m = first.true_translation_error_mm * 1e-3;
        run.start_off_deg = first.true_rotation_error_deg;
        run.final_translation_error_mm = last.true_translation_error_mm;
        run.final_rotation_error_deg = last.true_rotation_error_deg;
      }
      law.runs.push_back(run);
      if (progress) progress(++done, total);
    }
    report.laws.push_back(std::move(law));
  }
  return report;
}

}  // namespace oal
