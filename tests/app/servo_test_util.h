// Helpers shared by the servo app's tests.
#pragma once

#include <cstdint>
#include <string>

#include "app/config.h"
#include "app/servo_command.h"
#include "robots/robot.h"
#include "scene/scene.h"
#include "tests/app/command_test_util.h"

namespace oal::test {

/// Small images keep the suite fast: 320x240 with the same field of view.
inline ServoAppConfig Small(ServoAppConfig config) {
  config.camera.width = 320;
  config.camera.height = 240;
  config.camera.px = config.camera.py = 300.0;
  config.camera.u0 = 159.5;
  config.camera.v0 = 119.5;
  return config;
}

/// A shipped config/ file as `oalservo servo --config` reads it: over the built-in default.
inline ServoAppConfig ShippedServoConfig(const std::string& name) {
  ServoCommandOptions options;
  options.config_path = std::string(OAL_SOURCE_DIR) + "/config/" + name;
  return LoadServoConfig(options);
}

/// What the configured camera sees from cMo, as the servo loop's simulated camera renders it.
inline vpImage<unsigned char> CameraView(const ServoAppConfig& config,
                                         const vpHomogeneousMatrix& cMo, std::uint64_t seed) {
  RenderOptions render;
  render.width = config.camera.width;
  render.height = config.camera.height;
  render.camera = config.camera.Camera();
  render.noise_sigma = config.camera.noise;
  render.blur_sigma_px = config.camera.blur;
  return SceneRenderer(config.target, render).Render(cMo, seed).image;
}

inline bool SamePose(const vpHomogeneousMatrix& a, const vpHomogeneousMatrix& b) {
  const PoseDistance d = Distance(a, b);
  return d.translation_m < 1e-12 && d.rotation_rad < 1e-12;
}

}  // namespace oal::test
