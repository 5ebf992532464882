// Detect + pose of a printed A3 sheet (four-line-a3) on a bench, through TargetPoseTracker:
// a first frame (no prior: the sheet finder, its candidates' borders, the pose, the model
// check) and tracked frames (borders from the last pose), at 640x480 (px = 600, 56 degrees
// across) and 1920x1080 (px = 1371, a 70 degree webcam): the benchmarks' argument is the
// image's width. kdu 0.15 corrected, noise 2-8, blur 0.5-1.5, vignetting, the sheet's shadow
// and printed marks, clutter, on photographs of Debian's visp-images-data (uniform grey when
// it is missing). Frames are rendered once, outside the timed loops.
//   build/bench/bench_target --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>
#include <visp3/core/vpImageConvert.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "detector/lens.h"
#include "detector/sheet_finder.h"
#include "scene/bench_scene.h"
#include "scene/scene.h"
#include "servo/pbvs.h"
#include "servo/stripe_check.h"
#include "servo/target_tracker.h"

namespace oal {
namespace {

constexpr int kFrames = 32;

// Three of the photographs the accuracy commands use as benches
// (eval/rendered/rendered_frames.cpp).
std::vector<std::shared_ptr<const vpImage<unsigned char>>> BenchPhotos() {
  const std::string root = "/usr/share/visp-images-data/ViSP-images";
  std::vector<std::shared_ptr<const vpImage<unsigned char>>> photos;
  for (const char* name : {"Klimt/Klimt.pgm", "mire-2/image.0001.pgm", "cube/image.0000.pgm"}) {
    const std::string path = root + "/" + name;
    if (!std::filesystem::is_regular_file(path)) continue;
    const cv::Mat grey = cv::imread(path, cv::IMREAD_GRAYSCALE);
    if (grey.empty()) continue;
    auto photo = std::make_shared<vpImage<unsigned char>>();
    vpImageConvert::convert(grey, *photo);
    photos.push_back(std::move(photo));
  }
  if (photos.empty()) photos.push_back(nullptr);  // a uniform grey surface
  return photos;
}

// The camera of a benchmark's image width: 640x480 at 56 degrees across, or 1920x1080 at 70.
Lens CameraOfWidth(int width) {
  if (width == 1920) return Lens::WithKdu(1371.0, 1371.0, 959.5, 539.5, 0.15, 1920, 1080);
  return Lens::WithKdu(600.0, 600.0, 319.5, 239.5, 0.15, 640, 480);
}

RenderOptions BenchRender(std::shared_ptr<const vpImage<unsigned char>> photo, int index,
                          int width) {
  RenderOptions render;
  render.camera = CameraOfWidth(width);
  render.width = width;
  render.height = width == 1920 ? 1080 : 480;
  render.background = std::move(photo);
  DressAsBench(&render, 1 + static_cast<std::uint64_t>(index));
  return render;
}

FrameEffects EffectsOf(int frame) {
  FrameEffects effects;
  effects.noise_sigma = 2.0 + 6.0 * ((frame * 37) % kFrames) / (kFrames - 1.0);
  effects.blur_sigma_px = 0.5 + ((frame * 11) % kFrames) / (kFrames - 1.0);
  return effects;
}

struct TargetInputs {
  Lens camera;
  std::vector<RenderedFrame> still;   ///< random poses, each frame on its own
  std::vector<RenderedFrame> moving;  ///< a smooth sweep between two random poses
};

TargetInputs Render(int width) {
  TargetInputs built;
  const LineTarget target = FourLineA3Target();
  std::vector<SceneRenderer> renderers;
  int index = 0;
  for (auto& photo : BenchPhotos()) {
    renderers.emplace_back(target, BenchRender(photo, index++, width));
  }
  built.camera = renderers.front().options().camera;
  PoseSampling sampling = SheetSampling(target);  // as pose-accuracy views an A3 sheet
  std::uint64_t state = 1;
  for (int frame = 0; frame < kFrames; ++frame) {
    const SceneRenderer& renderer = renderers[frame % renderers.size()];
    built.still.push_back(
        renderer.Render(SamplePose(renderer, sampling, &state), frame, EffectsOf(frame)));
  }
  // About 3 mm and 0.3 deg a frame: a camera on an arm moving at a walking hand's pace.
  sampling.min_distance_m = 0.45;
  sampling.max_distance_m = 0.6;
  sampling.max_tilt_deg = 15.0;
  const SceneRenderer& renderer = renderers.front();
  const vpHomogeneousMatrix from = SamplePose(renderer, sampling, &state);
  const vpHomogeneousMatrix to = vpHomogeneousMatrix(0.05, -0.03, 0.04, 0.05, -0.05, 0.15) * from;
  const vpColVector xi = Se3Log(to * from.inverse());
  for (int frame = 0; frame < kFrames; ++frame) {
    const vpHomogeneousMatrix cMo = Se3Exp(xi * (frame / (kFrames - 1.0))) * from;
    built.moving.push_back(renderer.Render(cMo, 100 + frame, EffectsOf(frame)));
  }
  return built;
}

// The frames of a benchmark's image width, rendered on first use.
const TargetInputs& Inputs(const benchmark::State& state) {
  static std::map<int, TargetInputs> inputs;
  const int width = static_cast<int>(state.range(0));
  auto found = inputs.find(width);
  if (found == inputs.end()) found = inputs.emplace(width, Render(width)).first;
  return found->second;
}

// `frame` written into `delivered` (of its size), as a grabber writes each frame into the
// caller's image: the tracker then reads pixels the CPU has just written.
void Deliver(const vpImage<unsigned char>& frame, vpImage<unsigned char>* delivered) {
  std::copy(frame.bitmap, frame.bitmap + frame.getSize(), delivered->bitmap);
}

// The tracker told the rendered lens: in ViSP's model as rendered, or, when the benchmark's
// second argument is 1, as its OpenCV model (k1, k2, k3 fitted over the image: the same lens
// to a tenth of a pixel), whose undistortion is solved point by point.
TargetPoseTracker MakeTracker(const TargetInputs& inputs, const benchmark::State& state) {
  const int width = static_cast<int>(inputs.still.front().image.getWidth());
  const int height = static_cast<int>(inputs.still.front().image.getHeight());
  const Lens camera =
      state.range(1) == 1 ? inputs.camera.OpenCvCamera(width, height) : inputs.camera;
  DetectorOptions detector;
  PoseOptions pose;
  pose.camera = camera;
  pose.image_width = width;
  pose.image_height = height;
  pose.compute_covariance = false;
  return TargetPoseTracker(FourLineA3Target(), camera, detector, pose);
}

// The tracker's own step times and the frames it posed, over a benchmark's iterations.
struct StepTally {
  int ok = 0;
  double find_us = 0, detect_us = 0, pose_us = 0, candidates = 0;

  void Add(const TargetFrame& frame) {
    ok += frame.status == TargetStatus::kOk;
    find_us += frame.find_us;
    detect_us += frame.detect_us;
    pose_us += frame.pose_us;
    candidates += frame.candidates;
  }
  void Report(benchmark::State& state) const {
    const double n = static_cast<double>(state.iterations());
    state.counters["ok_fraction"] = ok / n;
    state.counters["find_us"] = find_us / n;
    state.counters["detect_us"] = detect_us / n;
    state.counters["pose_us"] = pose_us / n;
    state.counters["candidates"] = candidates / n;  // the sheet finder's, tried
  }
};

// A frame with no prior: what `oalservo pose` does on one image.
void TargetFirstFrame(benchmark::State& state) {
  const TargetInputs& inputs = Inputs(state);
  TargetPoseTracker tracker = MakeTracker(inputs, state);
  std::size_t frame = 0;
  StepTally tally;
  for (auto _ : state) {
    tracker.Reset();
    const TargetFrame& result = tracker.Track(ViewOf(inputs.still[frame].image));
    tally.Add(result);
    benchmark::DoNotOptimize(result.pose.cMo.data);
    frame = (frame + 1) % inputs.still.size();
  }
  tally.Report(state);
}

// As TargetFirstFrame, with each frame first copied into one image, untimed, as a camera
// delivers it (see TargetTrackedFromGrabber): `pose` on the first frame of a live camera.
void TargetFirstFrameFromGrabber(benchmark::State& state) {
  const TargetInputs& inputs = Inputs(state);
  TargetPoseTracker tracker = MakeTracker(inputs, state);
  vpImage<unsigned char> delivered = inputs.still.front().image;
  std::size_t frame = 0;
  StepTally tally;
  for (auto _ : state) {
    state.PauseTiming();
    Deliver(inputs.still[frame].image, &delivered);
    frame = (frame + 1) % inputs.still.size();
    tracker.Reset();
    state.ResumeTiming();
    const TargetFrame& result = tracker.Track(ViewOf(delivered));
    tally.Add(result);
    benchmark::DoNotOptimize(result.pose.cMo.data);
  }
  tally.Report(state);
}

// Frames of a moving camera, each tracked from the last pose; the sequence's first frame (found
// afresh) is not timed.
void TargetTracked(benchmark::State& state) {
  const TargetInputs& inputs = Inputs(state);
  TargetPoseTracker tracker = MakeTracker(inputs, state);
  tracker.Track(ViewOf(inputs.moving.front().image));
  std::size_t frame = 1;
  StepTally tally;
  for (auto _ : state) {
    const TargetFrame& result = tracker.Track(ViewOf(inputs.moving[frame].image));
    tally.Add(result);
    benchmark::DoNotOptimize(result.pose.cMo.data);
    if (++frame == inputs.moving.size()) {
      state.PauseTiming();
      tracker.Reset();
      tracker.Track(ViewOf(inputs.moving.front().image));
      frame = 1;
      state.ResumeTiming();
    }
  }
  tally.Report(state);
}

// As TargetTracked, with each frame first copied into one image, untimed, as a camera's
// frames arrive: vpV4l2Grabber::acquire converts the driver's buffer (YUYV or MJPG) into the
// caller's vpImage, so the tracker reads a frame the CPU has just written.
void TargetTrackedFromGrabber(benchmark::State& state) {
  const TargetInputs& inputs = Inputs(state);
  TargetPoseTracker tracker = MakeTracker(inputs, state);
  vpImage<unsigned char> delivered = inputs.moving.front().image;
  tracker.Track(ViewOf(delivered));
  std::size_t frame = 1;
  StepTally tally;
  for (auto _ : state) {
    state.PauseTiming();
    if (frame == inputs.moving.size()) {
      tracker.Reset();
      tracker.Track(ViewOf(inputs.moving.front().image));
      frame = 1;
    }
    Deliver(inputs.moving[frame++].image, &delivered);
    state.ResumeTiming();
    const TargetFrame& result = tracker.Track(ViewOf(delivered));
    tally.Add(result);
    benchmark::DoNotOptimize(result.pose.cMo.data);
  }
  tally.Report(state);
}

// The moving sequence's second frame tracked from its first: its pose and the detector's
// feature points, what the *Alone benchmarks take one step of a tracked frame from.
struct TrackedFrame {
  vpHomogeneousMatrix cMo;
  std::vector<FramePoint> points;
};
TrackedFrame TrackSecondFrame(const TargetInputs& inputs, const benchmark::State& state) {
  TargetPoseTracker tracker = MakeTracker(inputs, state);
  tracker.Track(ViewOf(inputs.moving.front().image));
  const TargetFrame& tracked = tracker.Track(ViewOf(inputs.moving[1].image));
  return TrackedFrame{tracked.pose.cMo, tracker.detector().feature_points()};
}

// The pose refined on the stripes' points alone (servo/stripe_fit.h), from a tracked frame's
// intersections' pose and feature points: its share of a tracked frame.
void StripeFitAlone(benchmark::State& state) {
  const TargetInputs& inputs = Inputs(state);
  const TrackedFrame tracked = TrackSecondFrame(inputs, state);
  const vpHomogeneousMatrix& start = tracked.cMo;
  const std::vector<FramePoint>& points = tracked.points;
  const TargetLayout layout = TargetLayout::Of(FourLineA3Target());
  int ok = 0, iterations = 0;
  for (auto _ : state) {
    const StripeFit fit = FitStripes(start, layout, points, inputs.camera, true);
    ok += fit.ok;
    iterations = fit.iterations;
    benchmark::DoNotOptimize(fit.cMo.data);
  }
  state.counters["ok_fraction"] = ok / static_cast<double>(state.iterations());
  state.counters["points"] = static_cast<double>(points.size());
  state.counters["iterations"] = iterations;
}

// The model check (servo/stripe_check.h) of a tracked frame's pose: its share of a tracked
// frame, the image as delivered (see TargetTrackedFromGrabber: copied in before each check).
void StripeCheckAlone(benchmark::State& state) {
  const TargetInputs& inputs = Inputs(state);
  const vpHomogeneousMatrix cMo = TrackSecondFrame(inputs, state).cMo;
  const TargetLayout layout = TargetLayout::Of(FourLineA3Target());
  // As the tracker checks: its settings in pixels scaled with the camera's focal length.
  const TargetTrackerOptions defaults;
  const StripeCheckOptions check =
      defaults.ScaledBy(defaults.PixelScale(inputs.camera)).StripeCheck();
  const vpImage<unsigned char>& frame = inputs.moving[1].image;
  vpImage<unsigned char> delivered = frame;
  int samples = 0, agreeing = 0;
  for (auto _ : state) {
    state.PauseTiming();
    Deliver(frame, &delivered);
    state.ResumeTiming();
    const StripeAgreement agreement =
        CheckStripes(ViewOf(delivered), layout, cMo, inputs.camera, check);
    samples =
        agreement.samples[0] + agreement.samples[1] + agreement.samples[2] + agreement.samples[3];
    agreeing = agreement.dark[0] + agreement.dark[1] + agreement.dark[2] + agreement.dark[3];
    benchmark::DoNotOptimize(agreement);
  }
  state.counters["samples"] = samples;
  state.counters["agreeing"] = agreeing;
}

// The sheet finder's look at a frame with no prior and the refinement of its best candidate
// (detector/sheet_finder.h): its share of a first frame, the image as delivered (copied in
// before each look, as TargetFirstFrameFromGrabber's).
void SheetFinderAlone(benchmark::State& state) {
  const TargetInputs& inputs = Inputs(state);
  const TargetTrackerOptions defaults;
  SheetFinder finder(defaults.ScaledBy(defaults.PixelScale(inputs.camera)).finder);
  vpImage<unsigned char> delivered = inputs.still.front().image;
  std::size_t frame = 0;
  double candidates = 0.0;
  for (auto _ : state) {
    state.PauseTiming();
    Deliver(inputs.still[frame].image, &delivered);
    frame = (frame + 1) % inputs.still.size();
    state.ResumeTiming();
    const GrayImageView view = ViewOf(delivered);
    std::vector<LightQuad> found = finder.Find(view);
    if (!found.empty()) finder.Refine(view, &found.front());
    candidates += static_cast<double>(found.size());
    benchmark::DoNotOptimize(found.data());
  }
  state.counters["candidates"] = candidates / static_cast<double>(state.iterations());
}

// Arguments: the image width, and the lens model the tracker is told (0: ViSP's, 1: OpenCV's).
BENCHMARK(TargetFirstFrame)
    ->Args({640, 0})
    ->Args({640, 1})
    ->Args({1920, 0})
    ->Args({1920, 1})
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(TargetFirstFrameFromGrabber)
    ->Args({640, 0})
    ->Args({1920, 0})
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(TargetTracked)
    ->Args({640, 0})
    ->Args({640, 1})
    ->Args({1920, 0})
    ->Args({1920, 1})
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(TargetTrackedFromGrabber)->Args({640, 0})->Args({1920, 0})->Unit(benchmark::kMicrosecond);
BENCHMARK(StripeFitAlone)->Args({640, 0})->Args({1920, 0})->Unit(benchmark::kMicrosecond);
BENCHMARK(StripeCheckAlone)->Args({640, 0})->Args({1920, 0})->Unit(benchmark::kMicrosecond);
BENCHMARK(SheetFinderAlone)->Args({640, 0})->Args({1920, 0})->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace oal

BENCHMARK_MAIN();
