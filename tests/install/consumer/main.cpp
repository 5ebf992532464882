// Renders the four-line target, finds its lines, estimates the camera pose and places a
// simulated camera there: one call into each installed library. Exit 0 when the pose is
// within 1 mm of the rendered one.
#include <visp3/core/vpHomogeneousMatrix.h>
#include <visp3/core/vpMath.h>

#include <iostream>

#include "detector/detector.h"
#include "robots/simulated_camera.h"
#include "scene/scene.h"
#include "servo/pose.h"

int main() {
  const oal::LineTarget target = oal::TargetByName("four-line");
  const oal::RenderOptions render;
  const vpHomogeneousMatrix cMo(0.01, -0.02, 0.6, vpMath::rad(5.0), 0.0, vpMath::rad(20.0));
  const oal::RenderedFrame frame = oal::SceneRenderer(target, render).Render(cMo, 1);

  oal::OalDetector detector(oal::DetectorOptions(), render.camera);
  const std::vector<oal::DetectedLine>& lines = detector.Detect(frame.image);

  oal::PoseOptions pose_options;
  pose_options.camera = render.camera;
  const oal::PoseResult pose = oal::EstimatePose(lines, target, pose_options);

  oal::SimulatedCamera robot;
  robot.SetPose(pose.cMo.inverse());

  const double error_m =
      (pose.cMo.getTranslationVector() - cMo.getTranslationVector()).frobeniusNorm();
  std::cout << lines.size() << " lines, pose "
            << (pose.status == oal::PoseStatus::kOk ? "ok" : "failed") << ", translation error "
            << error_m * 1000.0 << " mm\n";
  return pose.status == oal::PoseStatus::kOk && error_m < 1e-3 ? 0 : 1;
}
