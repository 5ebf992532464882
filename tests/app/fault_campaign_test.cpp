// The fault campaign on both robots, small: every kind of fault reached, every run judged
// from outside the loop (the controller simulator's wire tap, the driver's calls), none failed.
#include "app/fault_campaign.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "app/servo_command.h"
#include "servo_test_util.h"
#include "tests/app/command_test_util.h"
#include "tests/test_util.h"

namespace oal {
namespace {

using ::testing::HasSubstr;

// Each kind of fault `per_kind` times; checks what holds for every campaign.
FaultCampaignReport RunSmallCampaign(const ServoAppConfig& config, int per_kind,
                                     const test::TestDir& dir) {
  FaultCampaignOptions options;
  options.runs =
      per_kind * static_cast<int>(FaultKindsFor(FaultedRobotOf(config.robot.type)).size());
  options.work_dir = dir / "faults";
  options.jobs = 3;
  const FaultCampaignReport report = RunFaultCampaign(config, options);
  EXPECT_EQ(report.failed(), 0) << FaultCampaignTable(report);
  std::map<FaultKind, int> reached;
  for (const FaultRun& run : report.runs) {
    if (!run.reached) continue;
    ++reached[run.kind];
    EXPECT_EQ(run.moves_after_stop, 0);
    EXPECT_FALSE(run.message.empty());
    // Only a fault that takes the link may leave the stop unconfirmed, and only said so.
    if (run.stop_unconfirmed) {
      EXPECT_TRUE(run.kind == FaultKind::kPortClosed || run.kind == FaultKind::kControllerSilent ||
                  run.kind == FaultKind::kDriveTimeout)
          << ToString(run.kind) << ": " << run.message;
    } else {
      EXPECT_TRUE(run.robot_stopped) << ToString(run.kind) << ": " << run.message;
    }
    if (run.kind != FaultKind::kPortClosed) {
      EXPECT_TRUE(std::isfinite(run.fault_to_stop_ms)) << ToString(run.kind);
    }
  }
  for (const FaultKind kind : FaultKindsFor(FaultedRobotOf(config.robot.type))) {
    EXPECT_GE(reached[kind], 1) << ToString(kind) << " never reached";
  }
  // On either robot the loop holds past a short hand and a rolled frame, nothing commanded
  // meanwhile, and stops under a long hand.
  for (const FaultRun& run : report.runs) {
    if (!run.reached) continue;
    if (run.kind == FaultKind::kShortOcclusion || run.kind == FaultKind::kPoseJump) {
      EXPECT_EQ(run.status, ServoRunStatus::kConverged)
          << ToString(run.kind) << ": " << run.message;
      EXPECT_THAT(run.message, HasSubstr("held "));
      EXPECT_GE(run.spoiled_frames, 1);
      EXPECT_EQ(run.moves_while_held, 0);
    }
    if (run.kind == FaultKind::kLongOcclusion) {
      EXPECT_EQ(run.status, ServoRunStatus::kTargetLost) << run.message;
      EXPECT_THAT(run.message, HasSubstr("target lost: held "));
      EXPECT_EQ(run.moves_while_held, 0);
    }
  }
  // Runs that passed leave nothing behind.
  EXPECT_TRUE(std::filesystem::is_empty(dir / "faults")) << FaultCampaignTable(report);
  return report;
}

TEST(FaultCampaign, TheSimulatedRobotStopsOnEveryFault) {
  const test::TestDir dir;
  ServoAppConfig config = test::Small(DefaultServoConfig());
  const FaultCampaignReport report = RunSmallCampaign(config, 1, dir);
  for (const FaultRun& run : report.runs) {
    if (!run.reached) continue;
    if (run.kind == FaultKind::kUnreadableFrame) {
      EXPECT_THAT(run.message, HasSubstr("gave an empty frame"));
    }
    if (run.kind == FaultKind::kDriveTimeout) {
      EXPECT_THAT(run.message, HasSubstr("STOP COULD NOT BE SENT"));
    }
  }
}

TEST(FaultCampaign, TheScorbotStopsOnEveryFaultOfItsLink) {
  const test::TestDir dir;
  ServoAppConfig config = test::Small(test::ShippedServoConfig("scorbot-sim.yaml"));
  config.robot.simulator.throttle_to_baud = false;  // fast; the full campaign keeps 9600 baud
  config.robot.scorbot.reply_timeout_s = 0.3;
  const FaultCampaignReport report = RunSmallCampaign(config, 1, dir);
  const nlohmann::json json = nlohmann::json::parse(FaultCampaignJson(report));
  EXPECT_EQ(json["robot"], "scorbot");
  EXPECT_EQ(json["runs"].size(), report.runs.size());
  EXPECT_EQ(json["failed"], 0);
}

TEST(FaultCampaign, RefusesARealArmOrCamera) {
  const test::TestDir dir;
  FaultCampaignOptions options;
  options.runs = 1;
  options.work_dir = dir / "faults";
  ServoAppConfig config = test::ShippedServoConfig("scorbot-sim.yaml");
  config.robot.scorbot.port = "/dev/ttyUSB0";
  const std::string real_arm =
      test::ErrorMessageOf<std::invalid_argument>([&] { RunFaultCampaign(config, options); });
  EXPECT_THAT(real_arm, HasSubstr("drives the Controller-A simulator, never an arm: "));
  // Where the port was set: the shipped file, and the line.
  EXPECT_THAT(real_arm, ::testing::ContainsRegex(
                            "scorbot-sim.yaml:[0-9]+: robot.scorbot.port is '/dev/ttyUSB0', not "
                            "simulator"));
  config = DefaultServoConfig();
  config.source.type = SourceType::kReplay;
  config.source.path = "frames/";
  EXPECT_THAT(
      test::ErrorMessageOf<std::invalid_argument>([&] { RunFaultCampaign(config, options); }),
      HasSubstr("source.type must be simulated, not replay"));
  options.runs = 0;
  EXPECT_THAT(
      test::ErrorMessageOf<std::invalid_argument>(
          [&] { RunFaultCampaign(DefaultServoConfig(), options); }),
      HasSubstr("FaultCampaignOptions::runs = 0. Violated constraint: 1 <= runs <= 1000000"));
}

}  // namespace
}  // namespace oal
