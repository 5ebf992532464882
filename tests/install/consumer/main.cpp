// Renders the four-line target, finds its lines, scores them against the rendered truth,
// estimates the camera pose and places a simulated camera there: one call into each installed
// library; then a servo loop of loop/servo_loop.h on the A3 sheet, the simulated camera
// rendered in the loop. Exit 0 when the four lines match their truth, the pose is within 1 mm
// of the rendered one and the loop converges.
#include <visp3/core/vpHomogeneousMatrix.h>
#include <visp3/core/vpMath.h>

#include <iostream>
#include <sstream>

#include "detector/detector.h"
#include "detector/lens.h"
#include "eval/lines/line_scoring.h"
#include "loop/frame_source.h"
#include "loop/servo_loop.h"
#include "robots/simulated_camera.h"
#include "scene/scene.h"
#include "servo/pose.h"

namespace {

// The point-and-go law from 0.6 m, a little off to the side and turned, to 0.5 m in front of
// an A3 sheet lying at the world's origin.
bool ServoToTheSheet() {
  oal::ServoSetup setup;
  setup.target = oal::TargetByName("four-line-a3");
  const oal::RenderOptions render;
  setup.camera = render.camera;
  setup.width = render.width;
  setup.height = render.height;
  setup.loop.law.mode = oal::ServoMode::kPointAndGo;
  setup.cdMo = vpHomogeneousMatrix(0.0, 0.0, 0.5, 0.0, 0.0, 0.0);
  const vpHomogeneousMatrix start_cMo(0.03, -0.02, 0.6, vpMath::rad(4.0), vpMath::rad(-3.0),
                                      vpMath::rad(25.0));
  oal::SimulatedCameraOptions camera;
  camera.wMc = setup.wMo * start_cMo.inverse();
  oal::SimulatedCamera robot(camera);
  oal::RenderedFrames frames(setup.target, render);
  std::ostringstream log;
  const oal::ServoRunReport report = oal::RunServoLoop(setup, frames, robot, log);
  std::cout << "servo: " << oal::ToString(report.status) << ": " << report.message << "\n";
  return report.status == oal::ServoRunStatus::kConverged;
}

}  // namespace

int main() {
  const oal::LineTarget target = oal::TargetByName("four-line");
  const oal::RenderOptions render;
  const vpHomogeneousMatrix cMo(0.01, -0.02, 0.6, vpMath::rad(5.0), 0.0, vpMath::rad(20.0));
  const oal::RenderedFrame frame = oal::SceneRenderer(target, render).Render(cMo, 1);

  oal::OalDetector detector(oal::DetectorOptions(), render.camera);
  const std::vector<oal::DetectedLine>& lines = detector.Detect(frame.image);

  // The lines are in undistorted pixels (the detector was given the camera): so is the truth.
  const oal::PointUndistorter undistorter(render.camera);
  std::vector<oal::ReferenceLine> truth;
  for (const oal::TruthLine& line : frame.truth) {
    if (!line.visible) continue;
    truth.push_back(
        {line.ideal, undistorter.Undistort(line.end_a), undistorter.Undistort(line.end_b)});
  }
  std::vector<oal::LineParams> found;
  for (const oal::DetectedLine& line : lines) found.push_back(line.line);
  const std::size_t matched = oal::MatchLines(truth, found, 1.0, 2.0).size();

  oal::PoseOptions pose_options;
  pose_options.camera = render.camera;
  const oal::PoseResult pose = oal::EstimatePose(lines, target, pose_options);

  oal::SimulatedCamera robot;
  robot.SetPose(pose.cMo.inverse());

  const double error_m =
      (pose.cMo.getTranslationVector() - cMo.getTranslationVector()).frobeniusNorm();
  std::cout << lines.size() << " lines, " << matched << " matching the truth, pose "
            << (pose.status == oal::PoseStatus::kOk ? "ok" : "failed") << ", translation error "
            << error_m * 1000.0 << " mm\n";
  const bool converged = ServoToTheSheet();
  return matched == 4 && pose.status == oal::PoseStatus::kOk && error_m < 1e-3 && converged ? 0 : 1;
}
