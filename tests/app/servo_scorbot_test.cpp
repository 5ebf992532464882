// The servo app driving the Scorbot ER-VII through the real ACL driver over a pseudo-terminal,
// against the Controller-A simulator started by the loop (config/scorbot-sim.yaml).
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <visp3/core/vpMath.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <string>
#include <thread>

#include "app/config.h"
#include "app/scorbot_sim_command.h"
#include "app/servo_rig.h"
#include "app/servo_run.h"
#include "robots/scorbot_controller_sim.h"
#include "robots/scorbot_kinematics.h"
#include "servo_test_util.h"
#include "tests/app/command_test_util.h"
#include "tests/test_util.h"

namespace oal {
namespace {

using ::testing::HasSubstr;

// The shipped Scorbot run on small images, the simulated arm 20 times faster than real time
// and the link not paced at 9600 baud, so the test takes a second.
ServoAppConfig FastScorbot() {
  ServoAppConfig config = test::Small(test::ShippedServoConfig("scorbot-sim.yaml"));
  config.robot.simulator.time_scale = 20.0;
  config.robot.simulator.throttle_to_baud = false;
  return config;
}

TEST(ServoScorbot, Table3ThroughTheDriverAndTheControllerSimulatorConverges) {
  for (const ServoMode mode : {ServoMode::kExponential, ServoMode::kPointAndGo}) {
    ServoAppConfig config = FastScorbot();
    config.servo.law.mode = mode;
    std::ostringstream log;
    const ServoRunReport report = RunServo(config, log);
    ASSERT_EQ(report.status, ServoRunStatus::kConverged) << log.str() << report.message;
    EXPECT_LE(report.moves, 10) << log.str();  // 640x480 figures: docs/BENCHMARKS.md
    EXPECT_TRUE(report.robot_stopped);
    const ServoIteration& first = report.iterations.front();
    // The table shows the controller's own coordinates: Table 3's start point.
    EXPECT_NEAR(first.x_mm, 490.0, 0.2);
    EXPECT_NEAR(first.y_mm, 15.0, 0.2);
    EXPECT_NEAR(first.z_mm, 610.0, 0.2);
    EXPECT_NEAR(first.pitch_deg, -5.0, 0.11);
    const ServoIteration& last = report.iterations.back();
    EXPECT_NEAR(last.x_mm, 550.0, 2.0);  // 320x240 images: within a couple of mm
    EXPECT_NEAR(last.y_mm, -35.0, 2.0);
    EXPECT_NEAR(last.z_mm, 550.0, 2.0);
    EXPECT_LT(last.true_translation_error_mm, 3.0) << ToString(mode);
  }
}

// `oalservo scorbot-sim --config config/scorbot-sim.yaml` starts the arm where that file's
// camera sees the target, so the loop, connected to it as to a real controller, converges
// (at HOME it saw nothing).
TEST(ScorbotSimCommand, StartsTheArmAtTheConfigsStartForTheLoopToConverge) {
  const test::TestDir dir;
  ScorbotSimCommandOptions sim;
  sim.config_path = std::string(OAL_SOURCE_DIR) + "/config/scorbot-sim.yaml";
  sim.port_link = dir / "scorbot";
  sim.throttle = false;
  sim.time_scale = 20.0;
  std::atomic<bool> stop{false};
  std::ostringstream sim_out;
  std::thread server([&] { RunScorbotSimServer(sim, sim_out, &stop); });
  for (int i = 0; i < 500 && !std::filesystem::exists(sim.port_link); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ServoAppConfig config = FastScorbot();
  config.robot.scorbot.port = sim.port_link;
  std::ostringstream log;
  const ServoRunReport report = RunServo(config, log);
  stop = true;
  server.join();
  EXPECT_EQ(report.status, ServoRunStatus::kConverged) << log.str() << report.message;
  EXPECT_THAT(sim_out.str(), HasSubstr("the arm starts at robot.start of "));

  sim.config_path = std::string(OAL_SOURCE_DIR) + "/config/servo-sim.yaml";
  std::ostringstream out;
  EXPECT_THAT(
      test::ErrorMessageOf<std::invalid_argument>([&] { RunScorbotSimServer(sim, out, &stop); }),
      HasSubstr("robot.type is 'simulated', not scorbot"));
}

// A Controller-A simulator the test holds (to pull its cable, to make it hit something), with
// the arm at the configured start; the loop connects to it as to a real arm.
class HeldController {
 public:
  explicit HeldController(ServoAppConfig* config) : sim_(Options(*config)) {
    sim_.Start();
    config->robot.scorbot.port = sim_.DevicePath();
    config->robot.scorbot.reply_timeout_s = 0.5;
  }
  ScorbotControllerSim& sim() { return sim_; }

 private:
  static ScorbotSimOptions Options(const ServoAppConfig& config) {
    return ControllerSimOptions(config);  // as the loop starts its own
  }

  ScorbotControllerSim sim_;
};

// The cable pulled during the run: the stop cannot be sent, and the run must not say
// "robot stopped" (the controller may still be running its queued move).
TEST(ServoScorbot, AStopThatCannotBeSentIsReportedAsSuch) {
  ServoAppConfig config = FastScorbot();
  HeldController controller(&config);
  ServoRunHooks hooks;
  hooks.on_grab = [&](int iteration, cv::Mat*) {
    if (iteration == 2) controller.sim().Stop();  // before the move of iteration 2
  };
  std::ostringstream log;
  const ServoRunReport report = RunServo(config, log, hooks);
  EXPECT_EQ(report.status, ServoRunStatus::kError) << report.message;
  EXPECT_FALSE(report.robot_stopped);
  EXPECT_THAT(report.message, HasSubstr("; STOP COULD NOT BE SENT: scorbot: "));
  EXPECT_THAT(report.message, HasSubstr("the link to the controller is lost"));
  EXPECT_THAT(report.message, HasSubstr(" — check the arm"));
  EXPECT_THAT(report.message, ::testing::Not(HasSubstr("robot stopped")));
  EXPECT_THAT(report.message, ::testing::Not(HasSubstr("Connect()")));  // no API talk
}

// The arm stopped mid-move (an impact): the last row is where it stopped, read after the stop,
// not where the iteration began.
TEST(ServoScorbot, TheLastRowIsWhereTheArmStopped) {
  ServoAppConfig config = FastScorbot();
  HeldController controller(&config);
  ServoRunHooks hooks;
  hooks.on_frame = [&](const ServoFrame& frame) {
    // Halfway through the first move (frame 0's pose is confirmed on frame 1, which moves).
    if (frame.row.iteration == 1) controller.sim().InjectImpact(2);
  };
  std::ostringstream log;
  const ServoRunReport report = RunServo(config, log, hooks);
  EXPECT_EQ(report.status, ServoRunStatus::kError) << report.message;
  EXPECT_THAT(report.message, HasSubstr("IMPACT"));
  EXPECT_THAT(report.message, HasSubstr("; robot stopped"));
  EXPECT_TRUE(report.robot_stopped);
  ASSERT_EQ(report.iterations.size(), 3u) << log.str();
  EXPECT_EQ(report.moves, 1);  // begun, then stopped by the impact
  const ServoIteration& began = report.iterations[1];
  const ServoIteration& stopped = report.iterations[2];
  EXPECT_EQ(began.status, "error");
  EXPECT_EQ(stopped.status, "stopped");
  // Where the controller's arm is (the simulator's joints), in the table's ACL units.
  const AclPose arm = AclPoseOfJoints(config.robot.scorbot.geometry, controller.sim().joints());
  EXPECT_NEAR(stopped.x_mm, arm.x / 10.0, 0.2);
  EXPECT_NEAR(stopped.y_mm, arm.y / 10.0, 0.2);
  EXPECT_NEAR(stopped.z_mm, arm.z / 10.0, 0.2);
  const double moved_mm =
      std::hypot(stopped.x_mm - began.x_mm, stopped.y_mm - began.y_mm, stopped.z_mm - began.z_mm);
  EXPECT_GT(moved_mm, 5.0) << log.str();
}

TEST(ServoScorbot, VelocityLawIsRefusedBeforeTheArmMoves) {
  ServoAppConfig config = FastScorbot();
  config.servo.law.mode = ServoMode::kVelocity;
  std::ostringstream log;
  try {
    RunServo(config, log);
    FAIL() << "the position-only Scorbot must refuse the velocity law";
  } catch (const std::invalid_argument& error) {
    EXPECT_THAT(error.what(), HasSubstr("servo.mode velocity needs a robot driven in velocity"));
  }
}

TEST(ServoScorbot, AStartOutOfReachOrAMissingPortFailsClearly) {
  ServoAppConfig config = FastScorbot();
  config.robot.start_wMc = vpHomogeneousMatrix(2.0, 0.0, 0.5, 0.0, 0.0, 0.0);  // 2 m away
  std::ostringstream log;
  try {
    RunServo(config, log);
    FAIL();
  } catch (const std::invalid_argument& error) {
    EXPECT_THAT(error.what(), HasSubstr("robot.start is out of the Scorbot's reach"));
  }
  config = FastScorbot();
  config.robot.scorbot.port = "/dev/ttyOAL-missing";
  const ServoRunReport report = RunServo(config, log);
  EXPECT_EQ(report.status, ServoRunStatus::kError);
  EXPECT_THAT(report.message, HasSubstr("cannot connect the robot"));
  EXPECT_THAT(report.message, HasSubstr("/dev/ttyOAL-missing"));
  EXPECT_THAT(report.message, HasSubstr("robot.scorbot.port = '/dev/ttyOAL-missing')"));
  EXPECT_TRUE(report.iterations.empty());
  EXPECT_FALSE(report.started);
}

TEST(ServoScorbot, ConfigErrorsNameTheNestedKeyAndLine) {
  const auto error = [](const std::string& yaml) { return test::ConfigErrorOf(yaml, "arm.yaml"); };
  EXPECT_THAT(error("robot:\n  type: scorbot\n  scorbot:\n    speed_percent: 0\n"),
              HasSubstr("arm.yaml:4: 'robot.scorbot.speed_percent' is invalid"));
  EXPECT_THAT(error("robot:\n  scorbot:\n    geometry:\n      upper_arm_m: -0.3\n"),
              HasSubstr("arm.yaml:4: 'robot.scorbot.geometry.upper_arm_m' is invalid"));
  EXPECT_THAT(error("robot:\n  scorbot:\n    geometry:\n      home_deg: [0, 60]\n"),
              HasSubstr("'robot.scorbot.geometry.home_deg' must be a list of 5 numbers"));
  EXPECT_THAT(error("robot:\n  scorbot:\n    simulator:\n      time_scale: 0\n"),
              HasSubstr("arm.yaml:4: 'robot.scorbot.simulator.time_scale' is invalid"));
  EXPECT_THAT(error("robot:\n  scorbot:\n    parity: even\n"),
              HasSubstr("arm.yaml:3: key 'robot.scorbot.parity' is unknown"));
  EXPECT_THAT(error("robot:\n  type: puma\n"),
              HasSubstr("arm.yaml:2: 'robot.type' must be one of simulated, scorbot"));
  EXPECT_THAT(error("robot:\n  scorbot:\n    control_off_at_end: maybe\n"),
              HasSubstr("arm.yaml:3: 'robot.scorbot.control_off_at_end'"));
  // Read: off by default, on when asked.
  EXPECT_FALSE(DefaultServoConfig().robot.scorbot.control_off_at_end);
  const ServoAppConfig off =
      ParseConfig("robot:\n  scorbot:\n    control_off_at_end: true\n", "arm.yaml");
  EXPECT_TRUE(off.robot.scorbot.control_off_at_end);
}

}  // namespace
}  // namespace oal
