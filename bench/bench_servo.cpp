// One servo-loop iteration without rendering or capture: detect + pose (seeded by the
// previous estimate, as in the loop) + the control law, at 640x480, on frames rendered once
// outside the timed loop along an approach to the goal.
//   build/bench/bench_servo --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <optional>
#include <vector>

#include "detector/detector.h"
#include "scene/scene.h"
#include "servo/pbvs.h"
#include "servo/pose.h"

namespace oal {
namespace {

struct LoopInputs {
  RenderOptions render;
  std::vector<RenderedFrame> frames;
};

// 32 frames of servo-sim.yaml's camera (noise 2, blur 0.5) along an exponential approach to the
// goal (the target 0.5 m ahead) from a pose 0.1 m off and 10 deg turned.
const LoopInputs& Inputs() {
  static const LoopInputs inputs = [] {
    LoopInputs built;
    built.render.camera = vpCameraParameters(600.0, 600.0, 319.5, 239.5);
    built.render.noise_sigma = 2.0;
    built.render.blur_sigma_px = 0.5;
    const SceneRenderer renderer(FourLineTarget(), built.render);
    const vpHomogeneousMatrix cdMo(0.0, 0.0, 0.5, 0.0, 0.0, 0.0);
    const vpHomogeneousMatrix start_cMo =
        vpHomogeneousMatrix(0.1, -0.05, 0.1, 0.05, -0.17, 0.1) * cdMo;
    const vpColVector xi = Se3Log(cdMo * start_cMo.inverse());  // cdMc
    for (int frame = 0; frame < 32; ++frame) {
      const vpHomogeneousMatrix cdMc = Se3Exp(xi * (1.0 - frame / 32.0));
      built.frames.push_back(renderer.Render(cdMc.inverse() * cdMo, frame));
    }
    return built;
  }();
  return inputs;
}

void Iteration(benchmark::State& state, const DetectorOptions& detector_options) {
  const LoopInputs& inputs = Inputs();
  OalDetector detector(detector_options, inputs.render.camera);
  PoseOptions pose_options;
  pose_options.camera = inputs.render.camera;
  pose_options.lines_undistorted = detector.Undistorts();
  pose_options.image_width = 640;
  pose_options.image_height = 480;
  pose_options.compute_covariance = false;  // as in the loop (loop/servo_loop.cpp)
  const ServoOptions law;
  const LineTarget target = FourLineTarget();
  const vpHomogeneousMatrix cdMo(0.0, 0.0, 0.5, 0.0, 0.0, 0.0);
  std::optional<vpHomogeneousMatrix> previous;
  std::vector<LineSeed> seeds;
  std::size_t frame = 0;
  int ok = 0, from_previous = 0;
  for (auto _ : state) {
    const std::vector<DetectedLine>& lines =
        detector.Detect(ViewOf(inputs.frames[frame].image), seeds);
    const PoseResult pose = EstimatePose(lines, target, pose_options, previous);
    // Four seeds, as in the loop (loop/servo_loop.cpp seeds the target's lines projected from
    // the predicted pose; here the lines found, which costs the detector the same).
    seeds.clear();
    if (pose.status == PoseStatus::kOk) {
      for (int k = 0; k < 4; ++k) seeds.push_back(LineSeed{k + 1, lines[pose.line_index[k]].line});
    }
    if (pose.status == PoseStatus::kOk) {
      ++ok;
      from_previous += pose.method == PoseMethod::kPrevious;
      previous = pose.cMo;
      const ServoStep step = ComputeServoStep(pose.cMo, cdMo, law);
      benchmark::DoNotOptimize(step.c_T_cnew.data);
    }
    if (++frame == inputs.frames.size()) {
      frame = 0;
      previous.reset();  // the sequence starts over far from the last frame
      seeds.clear();
    }
  }
  const double n = static_cast<double>(state.iterations());
  state.counters["ok_fraction"] = ok / n;
  state.counters["previous_only_fraction"] = from_previous / n;
}

// The servo app's default detector (config/servo-sim.yaml: a border every 10 px).
DetectorOptions ServoDetector() {
  DetectorOptions options;
  options.step_px = 10;
  return options;
}

void LoopIteration(benchmark::State& state) {
  Iteration(state, ServoDetector());
}

// The paper's border step (5 px, config/detector.yaml): the trade-off docs/BENCHMARKS.md measures.
void LoopIterationBorderStep5(benchmark::State& state) {
  Iteration(state, DetectorOptions());
}

// Its three parts on their own, to show where the time goes.
void LoopDetectOnly(benchmark::State& state) {
  const LoopInputs& inputs = Inputs();
  OalDetector detector(ServoDetector(), inputs.render.camera);
  std::size_t frame = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(detector.Detect(inputs.frames[frame].image).data());
    frame = (frame + 1) % inputs.frames.size();
  }
}

void LoopPoseOnly(benchmark::State& state) {
  const LoopInputs& inputs = Inputs();
  OalDetector detector(ServoDetector(), inputs.render.camera);
  std::vector<std::vector<DetectedLine>> detections;
  for (const RenderedFrame& frame : inputs.frames)
    detections.push_back(detector.Detect(frame.image));
  PoseOptions pose_options;
  pose_options.camera = inputs.render.camera;
  pose_options.image_width = 640;
  pose_options.image_height = 480;
  pose_options.compute_covariance = false;
  const LineTarget target = FourLineTarget();
  std::vector<std::optional<vpHomogeneousMatrix>> previous(detections.size());
  for (std::size_t i = 1; i < detections.size(); ++i) {
    previous[i] = EstimatePose(detections[i - 1], target, pose_options).cMo;
  }
  std::size_t frame = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        EstimatePose(detections[frame], target, pose_options, previous[frame]).cMo.data);
    frame = (frame + 1) % detections.size();
  }
}

void LoopLawOnly(benchmark::State& state) {
  const vpHomogeneousMatrix cdMo(0.0, 0.0, 0.5, 0.0, 0.0, 0.0);
  const vpHomogeneousMatrix cMo = vpHomogeneousMatrix(0.1, -0.05, 0.1, 0.05, -0.17, 0.1) * cdMo;
  const ServoOptions law;
  for (auto _ : state) benchmark::DoNotOptimize(ComputeServoStep(cMo, cdMo, law).c_T_cnew.data);
}

BENCHMARK(LoopIteration)->Unit(benchmark::kMicrosecond);
BENCHMARK(LoopIterationBorderStep5)->Unit(benchmark::kMicrosecond);
BENCHMARK(LoopDetectOnly)->Unit(benchmark::kMicrosecond);
BENCHMARK(LoopPoseOnly)->Unit(benchmark::kMicrosecond);
BENCHMARK(LoopLawOnly)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace oal

BENCHMARK_MAIN();
