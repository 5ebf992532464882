// The fault campaign's pieces that need no servo job: the faults per robot, the refusal of a
// setup without a job, and the report's table and JSON. The campaign itself, on the configured
// servo job, is tested with the app (tests/app/fault_campaign_test.cpp).
#include "eval/campaigns/fault_campaign.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

namespace oal {
namespace {

using ::testing::HasSubstr;

TEST(FaultCampaign, EachRobotHasItsOwnFaultsAndTheFramesFaults) {
  const std::vector<FaultKind> arm = FaultKindsFor(FaultedRobot::kScorbot);
  const std::vector<FaultKind> drive = FaultKindsFor(FaultedRobot::kSimulated);
  EXPECT_EQ(arm.size(), 10u);
  EXPECT_EQ(drive.size(), 6u);
  EXPECT_EQ(arm.front(), FaultKind::kImpact);
  EXPECT_EQ(drive.front(), FaultKind::kDriveFault);
  for (const std::vector<FaultKind>* kinds : {&arm, &drive}) {
    EXPECT_EQ(kinds->back(), FaultKind::kPoseJump);
  }
  EXPECT_EQ(ToString(FaultKind::kXoffHeld), "xoff-held");
  EXPECT_EQ(ToString(FaultKind::kShortOcclusion), "short-occlusion");
  EXPECT_EQ(ToString(FaultKind::kLongOcclusion), "long-occlusion");
  EXPECT_EQ(ToString(FaultedRobot::kScorbot), "scorbot");
}

TEST(FaultCampaign, ASetupWithoutAServoJobIsRefusedBeforeAnyRun) {
  FaultCampaignOptions options;
  options.runs = 3;
  options.work_dir = testing::TempDir() + "/fault-campaign-no-job";
  EXPECT_THROW(RunFaultCampaign(FaultCampaignSetup{}, options), std::invalid_argument);
  options.runs = 0;
  FaultCampaignSetup setup;
  setup.run = [](const FaultRunRequest&, std::ostream&) { return ServoRunReport{}; };
  try {
    RunFaultCampaign(setup, options);
    FAIL() << "no error for 0 runs";
  } catch (const std::invalid_argument& error) {
    EXPECT_THAT(error.what(), HasSubstr("1 <= runs <= 1000000"));
  }
}

TEST(FaultCampaign, TheTableCountsEachFaultAndListsTheFailedRuns) {
  FaultCampaignReport report;
  report.robot = FaultedRobot::kSimulated;
  FaultRun stopped;
  stopped.kind = FaultKind::kDriveFault;
  stopped.reached = true;
  stopped.robot_stopped = true;
  stopped.fault_to_stop_ms = 12.0;
  FaultRun failed = stopped;
  failed.index = 1;
  failed.fault_at_s = 0.5;
  failed.moves_after_stop = 2;
  failed.problems = {"2 motion command(s) after the stop command"};
  report.runs = {stopped, failed};
  EXPECT_EQ(report.failed(), 1);
  const std::string table = FaultCampaignTable(report);
  EXPECT_THAT(table, HasSubstr("| drive-fault | 2 | 2 | 2 | 0 | 0 | 0 | 1 | 12 / 12 ms | 2 | 1 |"));
  EXPECT_THAT(table, HasSubstr("- run 1 (drive-fault at 0.5 s)"));
  EXPECT_THAT(table, HasSubstr("  - 2 motion command(s) after the stop command"));
  EXPECT_THAT(table, ::testing::Not(HasSubstr("| short-occlusion |")));  // no run: no row

  const nlohmann::json json = nlohmann::json::parse(FaultCampaignJson(report));
  EXPECT_EQ(json["robot"], "simulated");
  EXPECT_EQ(json["failed"], 1);
  ASSERT_EQ(json["runs"].size(), 2u);
  EXPECT_EQ(json["runs"][1]["moves_after_stop"], 2);
  EXPECT_EQ(json["runs"][1]["moves_while_held"], 0);
  EXPECT_TRUE(json["runs"][0]["final_true_translation_error_mm"].is_null());  // NaN: unknown
}

}  // namespace
}  // namespace oal
