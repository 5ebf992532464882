// A Robot that passes every call on to another: the base of decorators that watch or change
// a few calls of a driver (what reached it, faults injected) and leave the rest as they are.
#pragma once

#include <memory>
#include <string>
#include <utility>

#include "robots/robot.h"

namespace oal {

class ForwardingRobot : public Robot {
 public:
  explicit ForwardingRobot(std::unique_ptr<Robot> inner) : inner_(std::move(inner)) {}

  std::string Name() const override { return inner_->Name(); }
  RobotCapabilities Capabilities() const override { return inner_->Capabilities(); }
  RobotResult Connect() override { return inner_->Connect(); }
  RobotResult Enable() override { return inner_->Enable(); }
  RobotResult Disable() noexcept override { return inner_->Disable(); }
  RobotResult Stop() noexcept override { return inner_->Stop(); }
  RobotPose GetPosition(RobotFrame frame) override { return inner_->GetPosition(frame); }
  RobotResult StartMove(RobotFrame frame, const vpHomogeneousMatrix& target) override {
    return inner_->StartMove(frame, target);
  }
  MoveProgress PollMove() override { return inner_->PollMove(); }
  RobotResult SetVelocity(RobotFrame frame, const vpColVector& v) override {
    return inner_->SetVelocity(frame, v);
  }
  RobotPose NearestReachable(RobotFrame frame, const vpHomogeneousMatrix& target) override {
    return inner_->NearestReachable(frame, target);
  }
  RobotPose PoseAlongMove(RobotFrame frame, const vpHomogeneousMatrix& from,
                          const vpHomogeneousMatrix& target, double fraction) const override {
    return inner_->PoseAlongMove(frame, from, target, fraction);
  }
  vpHomogeneousMatrix eMc() const override { return inner_->eMc(); }
  std::string LinkSummary(int moves) const override { return inner_->LinkSummary(moves); }

 protected:
  Robot& inner() { return *inner_; }

 private:
  std::unique_ptr<Robot> inner_;
};

}  // namespace oal
