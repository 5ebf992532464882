// `oalservo servo-accuracy --faults N`: the fault campaign (eval/campaigns/fault_campaign.h) on the
// configuration's servo job, as `oalservo servo` runs it (outputs written, no window): a
// simulated camera, and the simulated robot or the Scorbot through its Controller-A simulator.
#pragma once

#include <functional>

#include "app/config.h"
#include "eval/campaigns/fault_campaign.h"

namespace oal {

/// The faults injected into the robot a configuration names.
FaultedRobot FaultedRobotOf(RobotType type);

/// Runs the campaign on `config` (robot.type scorbot with port "simulator", or simulated; a
/// simulated camera). Throws std::invalid_argument for a configuration it cannot run (a real
/// arm or camera) and std::runtime_error when the fault-free run does not converge.
FaultCampaignReport RunFaultCampaign(
    const ServoAppConfig& config, const FaultCampaignOptions& options,
    const std::function<void(int done, int total)>& progress = nullptr);

}  // namespace oal
