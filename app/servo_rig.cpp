#include "app/servo_rig.h"

#include <limits>
#include <stdexcept>
#include <utility>

#include "io/image_source.h"
#include "robots/scorbot_kinematics.h"
#include "robots/scorbot_robot.h"
#include "robots/simulated_camera.h"
#include "scene/scene.h"

namespace oal {
namespace {

// The simulated camera's lens, noise and blur; the scene's surface, light and clutter.
RenderOptions RenderOptionsOf(const ServoAppConfig& config) {
  const CameraConfig& camera = config.camera;
  RenderOptions render;
  config.scene.ApplyTo(&render);
  render.width = camera.width;
  render.height = camera.height;
  render.camera = camera.Camera();
  render.noise_sigma = camera.noise;
  render.blur_sigma_px = camera.blur;
  return render;
}

// The loop's fields as a configuration names them, for the loop's messages.
FieldNames ServoConfigNames() {
  return {{"width", "camera.width"},
          {"height", "camera.height"},
          {"estimate_distortion", "camera.estimate_distortion"},
          {"latency_s", "camera.latency_s"},
          {"loop.max_iterations", "servo.max_iterations"},
          {"loop.max_time_s", "servo.max_time_s"},
          {"loop.max_pose_jump_m", "servo.max_pose_jump_m"},
          {"loop.max_pose_jump_deg", "servo.max_pose_jump_deg"},
          {"loop.max_step_m", "servo.max_step_m"},
          {"loop.max_step_deg", "servo.max_step_deg"},
          {"loop.max_lost_frames", "servo.max_lost_frames"},
          {"loop.max_lost_s", "servo.max_lost_s"},
          {"loop.law.delta", "servo.delta"},
          {"loop.law.mode", "servo.mode"},
          {"safety.workspace_min_m", "robot.workspace_min_m"},
          {"safety.workspace_max_m", "robot.workspace_max_m"},
          {"calibrate", "oalservo calibrate"}};
}

}  // namespace

ServoSetup ServoSetupOf(const ServoAppConfig& config) {
  ServoSetup setup;
  setup.target = config.target;
  const CameraConfig& camera = config.camera;
  setup.camera = camera.correct_distortion && !camera.estimate_distortion
                     ? camera.Camera()
                     : vpCameraParameters(camera.px, camera.py, camera.u0, camera.v0);
  setup.width = camera.width;
  setup.height = camera.height;
  setup.estimate_distortion = camera.estimate_distortion;
  setup.detector = config.detector;
  setup.pose = config.pose;
  setup.tracking = config.tracking;
  setup.loop = config.servo;
  setup.safety = config.robot.safety;
  setup.wMo = config.target_wMo;
  setup.cdMo = config.goal_cdMo;
  setup.open_loop = config.source.type == SourceType::kReplay;
  setup.true_eMc = camera.true_eMc;
  setup.names = ServoConfigNames();
  return setup;
}

LoopRobot RobotRig::Loop() const {
  LoopRobot loop(*driver);
  loop.columns = columns;
  loop.has_yaw = has_yaw;
  loop.connect_hint = connect_hint;
  return loop;
}

ScorbotSimOptions ControllerSimOptions(const ServoAppConfig& config) {
  ScorbotSimOptions sim = config.robot.simulator;
  const ScorbotGeometry& geometry = config.robot.scorbot.geometry;
  sim.geometry = geometry;
  sim.baud = config.robot.scorbot.baud;
  const ScorbotReach start = NearestReachable(geometry, config.robot.start_wMc, config.camera.eMc);
  if (!start.ok) {
    throw std::invalid_argument("robot.start is out of the Scorbot's reach: " + start.why);
  }
  for (std::size_t i = 0; i < 5; ++i) sim.start_deg[i] = vpMath::deg(start.q[i]);
  return sim;
}

RobotRig OpenConfiguredRobot(const ServoAppConfig& config, std::function<void(int poll)> on_poll) {
  RobotRig rig;
  if (config.robot.type == RobotType::kScorbot) {
    ScorbotOptions options = config.robot.scorbot;
    options.eMc = config.camera.eMc;
    if (options.port == "simulator") {
      rig.controller = std::make_unique<ScorbotControllerSim>(ControllerSimOptions(config));
      rig.controller->Start();
      options.port = rig.controller->ConnectPath();
    }
    rig.driver = std::make_unique<ScorbotRobot>(options);
    // The controller's own X, Y, Z of the tool centre point and P, R (ACL); no free yaw.
    rig.columns = [eMc = config.camera.eMc](const vpHomogeneousMatrix& wMc) {
      const AclPose acl = ToAclPose(wMc * eMc.inverse());
      return PoseColumns{acl.x / 10.0, acl.y / 10.0, acl.z / 10.0,
                         acl.p / 10.0, acl.r / 10.0, std::numeric_limits<double>::quiet_NaN()};
    };
    rig.has_yaw = false;
    if (config.robot.scorbot.port != "simulator") {
      rig.connect_hint = " (check " + KeyAt(config, "robot.scorbot.port") + " = '" +
                         config.robot.scorbot.port + "')";
    }
    return rig;
  }
  SimulatedCameraOptions options;
  options.sampling_time_s = config.robot.sampling_time_s;
  // A move takes time, one sampling period per poll, as on an arm: a stop during it (Ctrl-C,
  // a limit) leaves the camera on its way.
  options.move_mode = SimulatedCameraOptions::MoveMode::kIntegrate;
  options.wMc = config.robot.start_wMc;
  options.eMc = config.camera.eMc;
  options.on_poll = std::move(on_poll);
  rig.driver = std::make_unique<SimulatedCamera>(options);
  return rig;
}

std::string KeyAt(const ServoAppConfig& config, const std::string& key) {
  const std::string origin = config.Origin(key);
  return origin.empty() ? key : origin + ": " + key;
}

std::unique_ptr<FrameSource> OpenFrames(const ServoAppConfig& config,
                                        std::vector<std::string>* warnings) {
  const SourceConfig& source = config.source;
  if (source.type == SourceType::kSimulated) {
    SimulatedCameraScene scene;
    scene.lived_in = config.scene.lived_in;
    scene.episode_s = config.scene.episode_s;
    scene.seed = static_cast<std::uint64_t>(config.scene.episode_seed);
    scene.exposure_s = config.camera.exposure_s;
    scene.latency_s = config.camera.latency_s;
    return std::make_unique<RenderedFrames>(config.target, RenderOptionsOf(config), scene);
  }
  const bool v4l2 = source.type == SourceType::kV4l2;
  const std::string key = v4l2 ? "source.device" : "source.path";
  try {
    if (v4l2) {
      V4l2Settings settings;
      settings.format = source.format;
      settings.width = source.width > 0 ? source.width : config.camera.width;
      settings.height = source.height > 0 ? source.height : config.camera.height;
      settings.fps = source.fps;
      return std::make_unique<RecordedFrames>(OpenV4l2Source(source.device, settings));
    }
    return std::make_unique<RecordedFrames>(OpenImageSource(source.path, warnings));
  } catch (const std::runtime_error& error) {
    throw std::runtime_error(KeyAt(config, key) + " '" + (v4l2 ? source.device : source.path) +
                             "' cannot be opened: " + error.what());
  }
}

}  // namespace oal
