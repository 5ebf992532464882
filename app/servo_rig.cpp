#include "app/servo_rig.h"

#include <cstdint>
#include <exception>
#include <limits>
#include <stdexcept>
#include <utility>

#include "app/lens_estimate.h"
#include "app/servo_loop.h"  // Table3Columns
#include "base/format.h"
#include "io/image_source.h"
#include "robots/scorbot_kinematics.h"
#include "robots/scorbot_robot.h"
#include "robots/simulated_camera.h"
#include "scene/scene.h"

namespace oal {
namespace {

constexpr std::uint64_t kNoiseSeed = 20240605;
// The frames read, the robot still, for camera.estimate_distortion (app/lens_estimate.h):
// their noise seeds apart from the loop's.
constexpr int kLensFrameIndex = 1000000;

// The simulated camera: the target rendered from the true pose with the configured lens,
// noise and blur.
class RenderedCamera : public LoopCamera {
 public:
  explicit RenderedCamera(const ServoAppConfig& config)
      : renderer_(config.target, RenderOptionsOf(config)) {}

  bool Grab(const vpHomogeneousMatrix& true_cMo, int iteration, cv::Mat* gray) override {
    frame_ = renderer_.Render(true_cMo, kNoiseSeed + static_cast<std::uint64_t>(iteration));
    *gray = cv::Mat(static_cast<int>(frame_.image.getHeight()),
                    static_cast<int>(frame_.image.getWidth()), CV_8UC1, frame_.image.bitmap);
    return true;
  }
  std::string Name() const override { return "the simulated camera"; }

 private:
  // The camera's lens, noise and blur; the scene's surface, light and clutter.
  static RenderOptions RenderOptionsOf(const ServoAppConfig& config) {
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

  SceneRenderer renderer_;
  RenderedFrame frame_;
};

// A V4L2 camera or a recording (io/image_source.h).
class SourceCamera : public LoopCamera {
 public:
  explicit SourceCamera(std::unique_ptr<ImageSource> source) : source_(std::move(source)) {}

  bool Grab(const vpHomogeneousMatrix& /*true_cMo*/, int /*iteration*/, cv::Mat* gray) override {
    if (peeked_ && peeked_error_) {
      // The frame AtEnd() read ahead could not be read: reported here, where it is taken.
      peeked_ = false;
      std::rethrow_exception(std::exchange(peeked_error_, nullptr));
    }
    const bool have_frame = peeked_ ? peeked_frame_ : source_->Next(&frame_);
    peeked_ = false;
    if (!have_frame) return false;
    *gray = frame_.gray;
    return true;
  }
  // Reads the next frame ahead (Grab() then hands it out); an unreadable one is not the end,
  // and the next Grab() throws its error.
  bool AtEnd() override {
    if (!peeked_) {
      try {
        peeked_frame_ = source_->Next(&frame_);
      } catch (const std::exception&) {
        peeked_error_ = std::current_exception();
      }
      peeked_ = true;
    }
    return !peeked_error_ && !peeked_frame_;
  }
  std::string Name() const override { return source_->Name(); }

 private:
  std::unique_ptr<ImageSource> source_;
  Frame frame_;
  bool peeked_ = false;              // frame_ holds the next frame already (AtEnd())
  bool peeked_frame_ = false;        // ... and there was one
  std::exception_ptr peeked_error_;  // ... or it could not be read
};

}  // namespace

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
  rig.columns = [](const vpHomogeneousMatrix& wMc) {
    PoseColumns c;
    Table3Columns(wMc, &c.x_mm, &c.y_mm, &c.z_mm, &c.pitch_deg, &c.roll_deg, &c.yaw_deg);
    return c;
  };
  return rig;
}

RobotPose TrueCameraPose(SafeRobot& robot, const ServoAppConfig& config) {
  if (!config.camera.true_eMc) return robot.GetPosition(RobotFrame::kCamera);
  RobotPose wMe = robot.GetPosition(RobotFrame::kEndEffector);
  if (wMe.result.ok()) wMe.pose = wMe.pose * *config.camera.true_eMc;
  return wMe;
}

bool TellTheLens(const ServoAppConfig& config, SafeRobot& robot, LoopCamera& frames,
                 LoopModel* model, TargetPoseTracker* tracker, std::ostream& log,
                 std::string* why) {
  cv::Mat gray;
  int read = 0;
  std::string pose_error;
  const ToldLens told = TellLensFromStripes(*tracker, model->camera, [&](GrayImageView* view) {
    const RobotPose at = TrueCameraPose(robot, config);
    if (!at.result.ok()) {
      pose_error = "the camera's pose cannot be read: " + at.result.message;
      return false;
    }
    if (!frames.Grab(at.pose.inverse() * config.target_wMo, kLensFrameIndex + read++, &gray)) {
      return false;
    }
    *view = ViewOf(gray);
    return true;
  });
  if (!told.lens) {
    *why = pose_error.empty() ? told.why : pose_error;
    return false;
  }
  const PlumbLineResult& lens = *told.lens;
  model->camera = WithLens(model->camera, lens);
  *tracker = model->Tracker();
  log << "lens told from the stripes of " << told.frames << " frames: kdu " << Fixed(lens.kdu, 4)
      << " +- " << Fixed(lens.kdu_sd, 4) << " (kud " << Fixed(lens.kud, 4) << ")"
      << " (they bent " << Fixed(lens.rms_before_px, 2) << " px RMS, "
      << Fixed(lens.rms_after_px, 2) << " px corrected)\n";
  return true;
}

std::string KeyAt(const ServoAppConfig& config, const std::string& key) {
  const std::string origin = config.Origin(key);
  return origin.empty() ? key : origin + ": " + key;
}

std::unique_ptr<LoopCamera> OpenLoopCamera(const ServoAppConfig& config,
                                           std::vector<std::string>* warnings) {
  const SourceConfig& source = config.source;
  if (source.type == SourceType::kSimulated) return std::make_unique<RenderedCamera>(config);
  const bool v4l2 = source.type == SourceType::kV4l2;
  const std::string key = v4l2 ? "source.device" : "source.path";
  try {
    if (v4l2) {
      V4l2Settings settings;
      settings.width = config.camera.width;
      settings.height = config.camera.height;
      settings.fps = source.fps;
      return std::make_unique<SourceCamera>(OpenV4l2Source(source.device, settings));
    }
    return std::make_unique<SourceCamera>(OpenImageSource(source.path, warnings));
  } catch (const std::runtime_error& error) {
    throw std::runtime_error(KeyAt(config, key) + " '" + (v4l2 ? source.device : source.path) +
                             "' cannot be opened: " + error.what());
  }
}

}  // namespace oal
