#include "eval/motion_audit.h"

#include <utility>

namespace oal {

class MotionAudit::Tap final : public Robot {
 public:
  Tap(std::unique_ptr<Robot> inner, MotionAudit* audit) : inner_(std::move(inner)), audit_(audit) {}

  std::string Name() const override { return inner_->Name(); }
  RobotCapabilities Capabilities() const override { return inner_->Capabilities(); }
  RobotResult Connect() override { return inner_->Connect(); }
  RobotResult Enable() override { return inner_->Enable(); }
  RobotResult Disable() noexcept override { return inner_->Disable(); }
  RobotResult Stop() noexcept override { return inner_->Stop(); }
  RobotPose GetPosition(RobotFrame frame) override { return inner_->GetPosition(frame); }
  RobotResult StartMove(RobotFrame frame, const vpHomogeneousMatrix& target) override {
    audit_->after_frame_.push_back(audit_->last_frame_);
    return inner_->StartMove(frame, target);
  }
  MoveProgress PollMove() override { return inner_->PollMove(); }
  RobotResult SetVelocity(RobotFrame frame, const vpColVector& v) override {
    if (v.frobeniusNorm() > 0.0) audit_->after_frame_.push_back(audit_->last_frame_);
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

 private:
  std::unique_ptr<Robot> inner_;
  MotionAudit* audit_;
};

std::unique_ptr<Robot> MotionAudit::Wrap(std::unique_ptr<Robot> driver) {
  return std::make_unique<Tap>(std::move(driver), this);
}

int MotionAudit::Unconfirmed(const ServoRunReport& report) const {
  int unconfirmed = 0;
  for (const int frame : after_frame_) {
    const bool acted = frame >= 0 && frame < static_cast<int>(report.iterations.size()) &&
                       report.iterations[static_cast<std::size_t>(frame)].status == "running";
    unconfirmed += !acted;
  }
  return unconfirmed;
}

}  // namespace oal
