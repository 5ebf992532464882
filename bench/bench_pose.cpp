// The pose step alone (identification + intersections + vpPose), on the detections of
// rendered four-line frames computed once outside the timed loop.
//   build/bench/bench_pose --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <vector>

#include "detector/detector.h"
#include "scene/scene.h"
#include "servo/pose.h"

namespace oal {
namespace {

struct PoseInputs {
  RenderOptions render;
  std::vector<std::vector<DetectedLine>> detections;
};

// 32 frames of the pose evaluation's kind: cheap wide lens, noise 8, blur 1, random poses.
const PoseInputs& Inputs() {
  static const PoseInputs inputs = [] {
    PoseInputs built;
    built.render.camera = Lens::WithKdu(600.0, 600.0, 319.5, 239.5, 0.33, 640, 480);
    built.render.noise_sigma = 8.0;
    built.render.blur_sigma_px = 1.0;
    const SceneRenderer renderer(FourLineTarget(), built.render);
    PoseSampling sampling;
    sampling.min_distance_m = 0.3;
    sampling.max_distance_m = 1.0;
    sampling.max_tilt_deg = 40.0;
    sampling.min_visible_length_px = 150.0;
    std::uint64_t state = 1;
    OalDetector detector(DetectorOptions(), built.render.camera);
    for (int frame = 0; frame < 32; ++frame) {
      const RenderedFrame rendered = renderer.Render(SamplePose(renderer, sampling, &state), frame);
      built.detections.push_back(detector.Detect(rendered.image));
    }
    return built;
  }();
  return inputs;
}

void PoseStep(benchmark::State& state) {
  const PoseInputs& inputs = Inputs();
  PoseOptions options;
  options.camera = inputs.render.camera;
  options.image_width = 640;
  options.image_height = 480;
  const LineTarget target = FourLineTarget();
  std::size_t frame = 0;
  int ok = 0;
  for (auto _ : state) {
    const PoseResult result = EstimatePose(inputs.detections[frame], target, options);
    ok += result.status == PoseStatus::kOk;
    benchmark::DoNotOptimize(result.cMo.data);
    frame = (frame + 1) % inputs.detections.size();
  }
  state.counters["ok_fraction"] = static_cast<double>(ok) / static_cast<double>(state.iterations());
}

void Identification(benchmark::State& state) {
  const PoseInputs& inputs = Inputs();
  PoseOptions options;
  options.camera = inputs.render.camera;
  const LineTarget target = FourLineTarget();
  std::size_t frame = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(IdentifyTargetLines(inputs.detections[frame], target, options));
    frame = (frame + 1) % inputs.detections.size();
  }
}

BENCHMARK(PoseStep)->Unit(benchmark::kMicrosecond);
BENCHMARK(Identification)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace oal

BENCHMARK_MAIN();
