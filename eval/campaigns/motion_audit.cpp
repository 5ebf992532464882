#include "eval/campaigns/motion_audit.h"

#include <utility>

#include "robots/forwarding_robot.h"

namespace oal {

class MotionAudit::Tap final : public ForwardingRobot {
 public:
  Tap(std::unique_ptr<Robot> inner, MotionAudit* audit)
      : ForwardingRobot(std::move(inner)), audit_(audit) {}

  RobotResult StartMove(RobotFrame frame, const vpHomogeneousMatrix& target) override {
    audit_->after_frame_.push_back(audit_->last_frame_);
    return inner().StartMove(frame, target);
  }
  RobotResult SetVelocity(RobotFrame frame, const vpColVector& v) override {
    if (v.frobeniusNorm() > 0.0) audit_->after_frame_.push_back(audit_->last_frame_);
    return inner().SetVelocity(frame, v);
  }

 private:
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
