// Soak: memory and file descriptors over long runs (docs/BENCHMARKS.md, "Soak"). Three parts;
// scripts/soak.sh runs them all and a long `oalservo evaluate`:
//   oal_soak tracker [--frames 100000]  the tracker + pose over a sheet seen from a moving
//                                       camera (re-acquired from scratch every 5000 frames):
//                                       resident memory after the warm-up, its maximum, the end
//   oal_soak links [--opens 10000]      the serial port opened and closed on the controller
//                                       simulator's pty, then the simulator's pty itself:
//                                       open file descriptors before and after
//   oal_soak video --out DIR [--frames 30000]  a long video of that sheet and its camera.xml,
//                                       for `oalservo evaluate`
// Each prints one line per measure and exits 1 when memory grew by more than 1 MB after the
// warm-up or a descriptor leaked.
#include <unistd.h>
#include <visp3/core/vpImageConvert.h>
#include <visp3/core/vpXmlParserCamera.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <opencv2/videoio.hpp>
#include <string>
#include <vector>

#include "detector/lens.h"
#include "robots/scorbot_controller_sim.h"
#include "robots/serial_port.h"
#include "scene/bench_scene.h"
#include "scene/scene.h"
#include "servo/pbvs.h"
#include "servo/target_tracker.h"

namespace oal {
namespace {

constexpr int kSweepFrames = 64;
constexpr long kAllowedGrowthKb = 1024;

long ResidentKb() {
  std::ifstream statm("/proc/self/statm");
  long pages = 0, resident = 0;
  statm >> pages >> resident;
  return resident * (::sysconf(_SC_PAGESIZE) / 1024);
}

int OpenDescriptors() {
  int count = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator("/proc/self/fd")) {
    ++count;
  }
  return count - 1;  // the iterator's own
}

RenderOptions SoakRender() {
  RenderOptions render;
  render.camera = Lens::WithKdu(600.0, 600.0, 319.5, 239.5, 0.15, 640, 480);
  DressAsBench(&render, 7);
  return render;
}

// A camera sweeping over the A3 sheet, about 3 mm and 0.3 deg a frame, and back.
std::vector<RenderedFrame> Sweep() {
  const LineTarget target = FourLineA3Target();
  const SceneRenderer renderer(target, SoakRender());
  PoseSampling sampling = SheetSampling(target);
  sampling.min_distance_m = 0.45;
  sampling.max_distance_m = 0.6;
  sampling.max_tilt_deg = 15.0;
  std::uint64_t state = 3;
  const vpHomogeneousMatrix from = SamplePose(renderer, sampling, &state);
  const vpHomogeneousMatrix to = vpHomogeneousMatrix(0.05, -0.03, 0.04, 0.05, -0.05, 0.15) * from;
  const vpColVector xi = Se3Log(to * from.inverse());
  std::vector<RenderedFrame> frames;
  for (int i = 0; i < kSweepFrames; ++i) {
    FrameEffects effects;
    effects.noise_sigma = 3.0;
    effects.blur_sigma_px = 0.8;
    frames.push_back(
        renderer.Render(Se3Exp(xi * (i / (kSweepFrames - 1.0))) * from, 100 + i, effects));
  }
  return frames;
}

// Frame i of the sweep played forward, backward, forward...
const RenderedFrame& PingPong(const std::vector<RenderedFrame>& frames, long i) {
  const long period = 2 * (static_cast<long>(frames.size()) - 1);
  const long at = i % period;
  return frames[static_cast<std::size_t>(at < static_cast<long>(frames.size()) ? at : period - at)];
}

int SoakTracker(long frames) {
  const std::vector<RenderedFrame> sweep = Sweep();
  const Lens camera = SoakRender().camera;
  PoseOptions pose;
  pose.camera = camera;
  pose.image_width = 640;
  pose.image_height = 480;
  pose.compute_covariance = false;
  TargetPoseTracker tracker(FourLineA3Target(), camera, DetectorOptions(), pose);
  const long warm_up = std::max(1L, frames / 10);
  long warm_kb = 0, max_kb = 0, posed = 0;
  for (long i = 0; i < frames; ++i) {
    if (i % 5000 == 0) tracker.Reset();
    posed += tracker.Track(ViewOf(PingPong(sweep, i).image)).status == TargetStatus::kOk;
    if (i + 1 == warm_up) warm_kb = max_kb = ResidentKb();
    if (i + 1 > warm_up && (i + 1) % 1000 == 0) max_kb = std::max(max_kb, ResidentKb());
  }
  const long end_kb = ResidentKb();
  max_kb = std::max(max_kb, end_kb);
  const bool flat = max_kb - warm_kb <= kAllowedGrowthKb;
  std::cout << "tracker: " << frames << " frames, " << posed << " posed; resident " << warm_kb
            << " kB after " << warm_up << " frames, at most " << max_kb << " kB after, " << end_kb
            << " kB at the end: growth " << max_kb - warm_kb << " kB (" << (flat ? "flat" : "GROWS")
            << ", allowed " << kAllowedGrowthKb << " kB)\n";
  return flat ? 0 : 1;
}

int SoakLinks(int opens) {
  ScorbotControllerSim sim;
  sim.Start();
  const int before = OpenDescriptors();
  const long before_kb = ResidentKb();
  int failures = 0;
  for (int i = 0; i < opens; ++i) {
    SerialPort port;
    failures += !port.Open(sim.DevicePath(), SerialPortOptions()).ok();
    port.Close();
  }
  const int after_port = OpenDescriptors();
  for (int i = 0; i < opens; ++i) {
    sim.Stop();
    sim.Start();
  }
  sim.Stop();
  sim.Start();
  const int after_pty = OpenDescriptors();
  const long after_kb = ResidentKb();
  const bool ok = failures == 0 && after_port == before && after_pty == before;
  std::cout << "links: serial port opened and closed " << opens << " times (" << failures
            << " failed), descriptors " << before << " -> " << after_port
            << "; the simulator's pty opened and closed " << opens << " times, descriptors "
            << after_pty << "; resident " << before_kb << " -> " << after_kb << " kB ("
            << (ok ? "no leak" : "LEAK") << ")\n";
  return ok ? 0 : 1;
}

int WriteVideo(const std::string& dir, long frames) {
  std::filesystem::create_directories(dir);
  const std::vector<RenderedFrame> sweep = Sweep();
  const std::string path = dir + "/sweep.avi";
  // MPEG-4 part 2, as evaluate's annotated videos: a few kB a frame (MJPG: 27 kB).
  cv::VideoWriter writer(path, cv::CAP_FFMPEG, cv::VideoWriter::fourcc('X', 'V', 'I', 'D'), 30.0,
                         cv::Size(640, 480), false);
  if (!writer.isOpened()) {
    std::cerr << "oal_soak video: cannot write " << path << "\n";
    return 1;
  }
  for (long i = 0; i < frames; ++i) {
    cv::Mat grey;
    vpImageConvert::convert(PingPong(sweep, i).image, grey);
    writer.write(grey);
  }
  writer.release();
  vpXmlParserCamera xml;
  const Lens camera = SoakRender().camera;
  std::filesystem::remove(dir + "/camera.xml");  // save() refuses a camera already there
  if (xml.save(camera.ViSPCamera(640, 480), dir + "/camera.xml", "Camera", 640, 480) !=
      vpXmlParserCamera::SEQUENCE_OK) {
    std::cerr << "oal_soak video: cannot write " << dir << "/camera.xml\n";
    return 1;
  }
  std::cout << "video: " << frames << " frames in " << path << ", its camera in " << dir
            << "/camera.xml\n";
  return 0;
}

}  // namespace
}  // namespace oal

int main(int argc, char** argv) {
  CLI::App cli{"Soak: memory and file descriptors over long runs (docs/BENCHMARKS.md)", "oal_soak"};
  cli.require_subcommand(1);
  long frames = 100000;
  int opens = 10000;
  long video_frames = 30000;
  std::string out;
  CLI::App* tracker = cli.add_subcommand("tracker", "the tracker + pose over a moving sheet");
  tracker->add_option("--frames", frames, "frames, >= 10")
      ->check(CLI::Range(10L, 100000000L))
      ->capture_default_str();
  CLI::App* links = cli.add_subcommand("links", "the serial port and the pty opened and closed");
  links->add_option("--opens", opens, "times each, >= 1")
      ->check(CLI::Range(1, 10000000))
      ->capture_default_str();
  CLI::App* video = cli.add_subcommand("video", "a long video and its camera.xml");
  video->add_option("--out", out, "folder")->required();
  video->add_option("--frames", video_frames, "frames, >= 1")
      ->check(CLI::Range(1L, 100000000L))
      ->capture_default_str();
  CLI11_PARSE(cli, argc, argv);
  if (tracker->parsed()) return oal::SoakTracker(frames);
  if (links->parsed()) return oal::SoakLinks(opens);
  return oal::WriteVideo(out, video_frames);
}
