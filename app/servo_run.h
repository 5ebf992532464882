// `oalservo servo`'s run from a configuration: the configuration checked, its frame source and
// robot opened (app/servo_rig.h), its goal taught, and the servo loop of loop/servo_loop.h run
// on them. A plain function that tests call directly; servo_command.h wraps it.
#pragma once

#include <functional>
#include <memory>
#include <ostream>

#include "app/config.h"
#include "loop/servo_loop.h"
#include "robots/robot.h"

namespace oal {

/// The loop's hooks (loop/servo_loop.h) and two for what the configuration opens.
struct ServoRunHooks : ServoLoopHooks {
  /// Tests: called at every poll of a position move of the simulated robot (robot.type
  /// simulated, whose moves take one sampling period per poll), with the iteration that
  /// commanded the move and the poll's number in it (0 first), e.g. to stop it on its way.
  std::function<void(int iteration, int poll)> on_move_poll;
  /// Tests and the fault campaign: wraps the driver the configuration opened (to watch what
  /// it is sent, to make it fail); the loop drives the wrapper in its place.
  std::function<std::unique_ptr<Robot>(std::unique_ptr<Robot>)> wrap_driver;
};

/// The goal of a taught configuration: the pose of config.target estimated in the image
/// config.goal_image with the configured camera and detector. Throws std::runtime_error naming
/// config.goal_image_origin and the image when it cannot be read, has another size than the
/// camera, or shows no pose.
vpHomogeneousMatrix TeachGoal(const ServoAppConfig& config);

/// Checks what the loop needs of a configuration beyond each section's own Check(): a V4L2
/// camera on a real robot, the lens either told or given, true_eMc only for a simulated
/// camera. Throws std::invalid_argument naming the key.
void CheckServoConfig(const ServoAppConfig& config);

/// Runs the loop on what the configuration opens (see the file comment). Writes one line per
/// iteration to `log`. Throws std::invalid_argument / std::runtime_error for a bad
/// configuration, before the robot moves.
ServoRunReport RunServo(const ServoAppConfig& config, std::ostream& log,
                        const ServoRunHooks& hooks = ServoRunHooks());

}  // namespace oal
