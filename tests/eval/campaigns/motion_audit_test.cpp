// The motion audit: each motion command the driver receives is tied to the last frame taken,
// and counted against the run's rows.
#include "eval/campaigns/motion_audit.h"

#include <gtest/gtest.h>

#include <memory>

#include "robots/simulated_camera.h"

namespace oal {
namespace {

ServoIteration Row(int iteration, const char* status) {
  ServoIteration row;
  row.iteration = iteration;
  row.status = status;
  return row;
}

TEST(MotionAudit, AMotionAfterAFrameTheLoopDidNotActOnIsCounted) {
  MotionAudit audit;
  std::unique_ptr<Robot> robot = audit.Wrap(std::make_unique<SimulatedCamera>());
  ASSERT_TRUE(robot->Connect().ok());
  ASSERT_TRUE(robot->Enable().ok());
  vpColVector twist(6, 0.0);
  audit.FrameTaken(0);  // found
  audit.FrameTaken(1);  // running: moves
  twist[0] = 0.01;
  ASSERT_TRUE(robot->SetVelocity(RobotFrame::kCamera, twist).ok());
  audit.FrameTaken(2);  // held: a zero twist is no motion
  ASSERT_TRUE(robot->SetVelocity(RobotFrame::kCamera, vpColVector(6, 0.0)).ok());
  audit.FrameTaken(3);  // found again, yet a move: unconfirmed
  ASSERT_TRUE(robot->StartMove(RobotFrame::kCamera, vpHomogeneousMatrix()).ok());
  ServoRunReport report;
  report.iterations = {Row(0, "found"), Row(1, "running"), Row(2, "held"), Row(3, "held")};
  EXPECT_EQ(audit.motions(), 2);
  EXPECT_EQ(audit.Unconfirmed(report), 1);
  report.iterations[3].status = "running";
  EXPECT_EQ(audit.Unconfirmed(report), 0);
}

}  // namespace
}  // namespace oal
