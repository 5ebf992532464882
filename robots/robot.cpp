#include "robots/robot.h"

#include <visp3/core/vpExponentialMap.h>
#include <visp3/core/vpThetaUVector.h>

namespace oal {

std::string ToString(RobotStatus status) {
  switch (status) {
    case RobotStatus::kOk:
      return "ok";
    case RobotStatus::kError:
      return "error";
    case RobotStatus::kStopped:
      return "stopped";
    case RobotStatus::kNotReady:
      return "not-ready";
    case RobotStatus::kLimit:
      return "limit";
    case RobotStatus::kWorkspace:
      return "workspace";
    case RobotStatus::kUnreachable:
      return "unreachable";
    case RobotStatus::kUnsupported:
      return "unsupported";
    case RobotStatus::kTimeout:
      return "timeout";
  }
  return "unknown";
}

std::string ToString(RobotFrame frame) {
  switch (frame) {
    case RobotFrame::kCamera:
      return "camera";
    case RobotFrame::kEndEffector:
      return "end-effector";
  }
  return "unknown";
}

RobotPose Robot::PoseAlongMove(RobotFrame /*frame*/, const vpHomogeneousMatrix& from,
                               const vpHomogeneousMatrix& target, double fraction) const {
  // A constant twist applied for a fraction of the move's time: exactly what
  // SimulatedCamera's kIntegrate move reaches after that many of its sampling periods.
  const vpColVector screw = vpExponentialMap::inverse(from.inverse() * target, 1.0);
  RobotPose p;
  p.pose = from * vpExponentialMap::direct(screw, fraction);
  return p;
}

}  // namespace oal
