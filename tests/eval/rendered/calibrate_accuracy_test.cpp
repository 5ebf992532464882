// The calibration's evaluation (eval/rendered/calibrate_accuracy.h) with a given lens in OpenCV's
// model: every camera is that lens, the lens found is judged by its ideal pixels, and a lens
// that folds over inside the image is refused.
#include "eval/rendered/calibrate_accuracy.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <stdexcept>

#include "detector/lens.h"
#include "scene/bench_scene.h"

namespace oal {
namespace {

const Lens kSample =
    Lens::WithDistortion(535.9157, 535.9157, 342.2832, 235.5708,
                         {-0.266373, -0.0385889, 0.00178319, -0.000281221, 0.238392});

TEST(CalibrateAccuracy, AGivenLensIsCalibratedAndJudgedByItsIdealPixels) {
  CalibrateAccuracyOptions options;
  options.lens = kSample;
  options.cameras = 1;
  options.frames = 8;
  options.seed = 3;
  options.noise_sigma = 2.0;
  options.blur_sigma_px = 0.8;
  options.sampling = SheetSampling(options.target);
  options.sampling.max_tilt_deg = 45.0;
  const std::vector<CameraCalibrationTrial> trials = EvaluateCalibration(options);
  ASSERT_EQ(trials.size(), 1u);
  const CameraCalibrationTrial& trial = trials.front();
  ASSERT_TRUE(trial.failed.empty()) << trial.failed;
  EXPECT_EQ(trial.truth, kSample);
  EXPECT_EQ(trial.found.model(), Lens::Model::kOpenCV);
  EXPECT_LT(trial.px_error_pct(), 0.5);
  EXPECT_EQ(trial.lens_error_px,
            WorstIdealPixelDifference(trial.found, kSample, 640, 480,
                                      kLensJudgedFraction * 0.5 * std::hypot(640.0, 480.0)));
}

TEST(CalibrateAccuracy, ALensThatFoldsOverInsideTheImageIsRefused) {
  CalibrateAccuracyOptions options;
  options.lens = Lens::WithDistortion(400.0, 400.0, 319.5, 239.5, {-0.6, 0.0, 0.0, 0.0, 0.0});
  EXPECT_THROW(options.Check(), std::invalid_argument);
  options.lens = kSample;
  EXPECT_NO_THROW(options.Check());
}

}  // namespace
}  // namespace oal
