// Detector speed on rendered frames, against OpenCV's line detectors on the same frames.
//   build/bench/bench_detector --benchmark_repetitions=5 --benchmark_report_aggregates_only
// Frames are rendered once, outside the timed loops. All timings are single-threaded.
#include <benchmark/benchmark.h>

#include <map>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <tuple>
#include <vector>

#include "detector/border_scan.h"
#include "detector/detector.h"
#include "scene/scene.h"

namespace oal {
namespace {

// The accuracy evaluation's cheap camera (kdu 0.33), noise 8, blur 1, scaled to the size.
RenderOptions CheapCamera(int width, int height) {
  RenderOptions options;
  options.width = width;
  options.height = height;
  const double f = 600.0 * width / 640.0;
  options.camera = Lens::WithKudKdu(f, f, 0.5 * (width - 1), 0.5 * (height - 1), 0.0, 0.33);
  options.noise_sigma = 8.0;
  options.blur_sigma_px = 1.0;
  return options;
}

// A frame of the named target seen from a fixed, slightly tilted pose, rendered once.
const RenderedFrame& Frame(const std::string& target, int width, int height) {
  static std::map<std::tuple<std::string, int, int>, RenderedFrame> cache;
  const auto key = std::make_tuple(target, width, height);
  auto it = cache.find(key);
  if (it == cache.end()) {
    const SceneRenderer renderer(TargetByName(target), CheapCamera(width, height));
    vpHomogeneousMatrix cMo(0.01, -0.02, 0.6, vpMath::rad(8.0), vpMath::rad(-5.0),
                            vpMath::rad(20.0));
    it = cache.emplace(key, renderer.Render(cMo, 1)).first;
  }
  return it->second;
}

cv::Mat MatOf(const RenderedFrame& frame) {
  return cv::Mat(static_cast<int>(frame.image.getHeight()),
                 static_cast<int>(frame.image.getWidth()), CV_8UC1,
                 const_cast<unsigned char*>(frame.image.bitmap));
}

// A synthetic frame with `count` straight stripes in varied directions.
vpImage<unsigned char> StripesFrame(int count) {
  cv::Mat image(480, 640, CV_8UC1, cv::Scalar(210));
  for (int i = 0; i < count; ++i) {
    const double theta = kPi * (0.07 + i) / count;
    const double rho = 320.0 * std::cos(theta) + 240.0 * std::sin(theta) + 60.0 * ((i % 3) - 1);
    const cv::Point2d foot(rho * std::cos(theta), rho * std::sin(theta));
    const cv::Point2d dir(-std::sin(theta), std::cos(theta));
    cv::line(image, foot - 2000.0 * dir, foot + 2000.0 * dir, cv::Scalar(30), 6, cv::LINE_AA);
  }
  cv::Mat noise(image.size(), CV_16SC1);
  cv::RNG rng(5);
  rng.fill(noise, cv::RNG::NORMAL, 0, 8);
  cv::Mat noisy;
  image.convertTo(noisy, CV_16SC1);
  noisy += noise;
  noisy.convertTo(image, CV_8UC1);
  vpImage<unsigned char> out(480, 640);
  std::memcpy(out.bitmap, image.data, 640 * 480);
  return out;
}

void Oal(benchmark::State& state, const std::string& target, bool undistort) {
  const int width = static_cast<int>(state.range(0)), height = static_cast<int>(state.range(1));
  const RenderedFrame& frame = Frame(target, width, height);
  OalDetector detector = undistort
                             ? OalDetector(DetectorOptions(), CheapCamera(width, height).camera)
                             : OalDetector(DetectorOptions());
  std::size_t found = 0;
  for (auto _ : state) {
    const auto& lines = detector.Detect(frame.image);
    found = lines.size();
    benchmark::DoNotOptimize(lines.data());
  }
  state.counters["lines"] = static_cast<double>(found);
}

// The four-line 640x480 frame with a border every state.range(0) px (the paper: 5; the servo
// configuration, config/servo-sim.yaml: 10), points undistorted.
void OalBorderStep(benchmark::State& state) {
  const RenderedFrame& frame = Frame("four-line", 640, 480);
  DetectorOptions options;
  options.step_px = static_cast<int>(state.range(0));
  OalDetector detector(options, CheapCamera(640, 480).camera);
  std::size_t found = 0;
  for (auto _ : state) {
    found = detector.Detect(frame.image).size();
    benchmark::ClobberMemory();
  }
  state.counters["lines"] = static_cast<double>(found);
}

// Step 1 alone on the four-line 640x480 frame, as Detect() runs it at the default (paper)
// parameters: every border read, its Otsu threshold and its feature points; no pairs, no
// votes. Shows what the pixels cost before any voting.
void OalBordersOnly(benchmark::State& state) {
  const RenderedFrame& frame = Frame("four-line", 640, 480);
  const GrayImageView view = ViewOf(frame.image);
  const DetectorOptions options;
  BorderLoops loops;
  loops.Prepare(view.width, view.height, options.start_px, options.step_px);
  std::vector<BorderPoint> points;
  points.reserve(static_cast<std::size_t>(options.max_points_per_border));
  int found = 0;
  for (auto _ : state) {
    found = 0;
    loops.Read(view);
    for (int k = 0; k < loops.count(); ++k) {
      const std::vector<std::uint8_t>& samples = loops.Gather(view, k);
      int contrast = 0;
      const int threshold = OtsuThreshold(samples, &contrast);
      points.clear();
      if (contrast >= options.min_contrast) {
        found += FindBorderPoints(samples, loops.Rect(k), threshold, options, &points);
      }
    }
    benchmark::ClobberMemory();
  }
  state.counters["points"] = found;
}

void OalPaper(benchmark::State& state) {
  const RenderedFrame& frame = Frame("four-line", 640, 480);
  OalDetector detector(DetectorOptions::Paper());
  for (auto _ : state) benchmark::DoNotOptimize(detector.Detect(frame.image).data());
}

void OalLineCount(benchmark::State& state) {
  const vpImage<unsigned char> image = StripesFrame(static_cast<int>(state.range(0)));
  DetectorOptions options;
  options.max_output_lines = 16;
  OalDetector detector(options);
  std::size_t found = 0;
  for (auto _ : state) {
    found = detector.Detect(image).size();
    benchmark::ClobberMemory();
  }
  state.counters["lines"] = static_cast<double>(found);
}

// OpenCV's classical pipelines, as a user would write them.
void CvThresholdCannyHough(benchmark::State& state) {
  const cv::Mat image = MatOf(Frame("four-line", 640, 480));
  cv::Mat binary, edges;
  std::vector<cv::Vec2f> lines;
  for (auto _ : state) {
    cv::threshold(image, binary, 0, 255, cv::THRESH_BINARY | cv::THRESH_OTSU);
    cv::Canny(binary, edges, 50, 150);
    cv::HoughLines(edges, lines, 1.0, CV_PI / 180.0, 120);
    benchmark::DoNotOptimize(lines.data());
  }
  state.counters["lines"] = static_cast<double>(lines.size());
}

void CvCannyHough(benchmark::State& state) {
  const cv::Mat image = MatOf(Frame("four-line", 640, 480));
  cv::Mat edges;
  std::vector<cv::Vec2f> lines;
  for (auto _ : state) {
    cv::Canny(image, edges, 50, 150);
    cv::HoughLines(edges, lines, 1.0, CV_PI / 180.0, 120);
    benchmark::DoNotOptimize(lines.data());
  }
  state.counters["lines"] = static_cast<double>(lines.size());
}

void CvCannyHoughP(benchmark::State& state) {
  const cv::Mat image = MatOf(Frame("four-line", 640, 480));
  cv::Mat edges;
  std::vector<cv::Vec4i> lines;
  for (auto _ : state) {
    cv::Canny(image, edges, 50, 150);
    cv::HoughLinesP(edges, lines, 1.0, CV_PI / 180.0, 80, 100, 10);
    benchmark::DoNotOptimize(lines.data());
  }
  state.counters["lines"] = static_cast<double>(lines.size());
}

void CvLsd(benchmark::State& state) {
  const cv::Mat image = MatOf(Frame("four-line", 640, 480));
  const cv::Ptr<cv::LineSegmentDetector> lsd = cv::createLineSegmentDetector();
  std::vector<cv::Vec4f> lines;
  for (auto _ : state) {
    lsd->detect(image, lines);
    benchmark::DoNotOptimize(lines.data());
  }
  state.counters["lines"] = static_cast<double>(lines.size());
}

BENCHMARK_CAPTURE(Oal, two_line, std::string("two-line"), true)
    ->Args({640, 480})
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(Oal, four_line, std::string("four-line"), true)
    ->Args({320, 240})
    ->Args({640, 480})
    ->Args({1280, 720})
    ->Args({1920, 1080})
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(Oal, four_line_no_undistortion, std::string("four-line"), false)
    ->Args({640, 480})
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(OalBorderStep)->Arg(5)->Arg(10)->Unit(benchmark::kMicrosecond);
BENCHMARK(OalBordersOnly)->Unit(benchmark::kMicrosecond);
BENCHMARK(OalPaper)->Unit(benchmark::kMicrosecond);
BENCHMARK(OalLineCount)->Arg(1)->Arg(2)->Arg(4)->Arg(8)->Unit(benchmark::kMicrosecond);
BENCHMARK(CvThresholdCannyHough)->Unit(benchmark::kMicrosecond);
BENCHMARK(CvCannyHough)->Unit(benchmark::kMicrosecond);
BENCHMARK(CvCannyHoughP)->Unit(benchmark::kMicrosecond);
BENCHMARK(CvLsd)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace oal

BENCHMARK_MAIN();
