// What reached the robot, set against the frames: each motion command a driver received (a
// move started, a non-zero twist) is tied to the last frame the loop had taken when it came.
// A command may only follow a frame the loop acted on ("running": a confirmed pose); one that
// follows a frame it held at, found a pose to confirm in, or skipped was sent from a pose that
// was not confirmed. The audit sits outside the loop: between the driver and the loop (a
// decorator of the driver) and at the frame source (ServoLoopHooks::on_grab).
#pragma once

#include <memory>
#include <vector>

#include "loop/servo_loop.h"
#include "robots/robot.h"

namespace oal {

class MotionAudit {
 public:
  /// `driver` seen through the audit: the loop drives the returned robot in its place. The
  /// audit must outlive it.
  std::unique_ptr<Robot> Wrap(std::unique_ptr<Robot> driver);
  /// To be called with each frame the loop takes (ServoLoopHooks::on_grab).
  void FrameTaken(int iteration) { last_frame_ = iteration; }

  /// Motion commands the robot received.
  int motions() const { return static_cast<int>(after_frame_.size()); }
  /// ... of which after a frame whose row in `report` is not "running" (or before any frame).
  int Unconfirmed(const ServoRunReport& report) const;

 private:
  class Tap;
  int last_frame_ = -1;
  std::vector<int> after_frame_;  ///< per motion command, the last frame taken before it
};

}  // namespace oal
