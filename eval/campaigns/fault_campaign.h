// The fault campaign of the servo loop: N runs of one servo job (the caller's: `oalservo
// servo-accuracy --faults N` hands it the configured `oalservo servo` run, outputs written), each
// with one fault injected at a random moment (fixed seed), each judged from outside the loop:
//   - the run's report (the loop's) ends with the robot stopped and says why it ended; where
//     the fault takes the link itself (the port closed, a silent controller, a drive that
//     stops answering), the stop cannot be confirmed and the report must say so;
//   - no motion command reaches the robot after the stop command that followed the fault;
//   - the time from the fault to that stop command;
//   - the output folder holds whole files only: images that decode, no temporary file, and
//     the job's own files whole as the job judges them (the caller's check: a CSV with
//     every row);
//   - a run the fault did not stop (line noise the driver could ignore, a short occlusion or
//     a rolled frame the loop held past) ends at the goal as a fault-free run does (the
//     simulation's truth); a frame fault the loop must hold past (short-occlusion, pose-jump)
//     gets no motion command from its first spoiled frame until the second frame after its
//     last (found again, then confirmed), and a long occlusion none after its first frame;
//     a zero twist holds the robot and is no motion.
// Where the commands are watched: for the Scorbot, on the wire: the Controller-A simulator, run
// here rather than by the job, logs every line it receives with its arrival time (a "MOVE" is a
// motion command, Ctrl-A the stop); for the simulated robot, a wrapper of its driver logs every
// call.
// The moment: uniform over the first 85 % of a fault-free run (timed first); an impact waits
// for the arm to move, a frame fault spoils the first frame taken after it. A run that let go of
// the robot (its final stop) before its fault's moment is run again with the moment halved,
// up to 4 times; then it is "not reached" and not judged.
#pragma once

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "loop/servo_loop.h"
#include "robots/robot.h"
#include "robots/scorbot_controller_sim.h"

namespace oal {

/// What the faults are injected into: the simulated robot's drive (its driver wrapped), or the
/// Scorbot's serial link (the Controller-A simulator the campaign runs).
enum class FaultedRobot { kSimulated, kScorbot };

enum class FaultKind {
  kImpact,            ///< Scorbot: the arm hits something (IMPACT PROTECTION, control off)
  kControllerSilent,  ///< Scorbot: the controller hangs (nothing executed, nothing answered)
  kReplyCut,          ///< Scorbot: a reply cut short, its prompt lost
  kLineNoise,         ///< Scorbot: random bytes amid the controller's output
  kPortClosed,        ///< Scorbot: the serial link goes away (cable, adapter)
  kXoffHeld,          ///< Scorbot: XOFF from the controller and no XON after it
  kDriveFault,        ///< simulated robot: every motion and read call fails from now on
  kDriveTimeout,      ///< simulated robot: every call, the stop too, times out from now on
  kUnreadableFrame,   ///< the camera gives no frame
  /// A hand (a dark blob) over the whole view for fewer frames than the loop holds for: the
  /// run must hold, carry on and converge, no motion commanded while it holds.
  kShortOcclusion,
  /// ... for the rest of the run: it must stop (target-lost), nothing moving after the hand.
  kLongOcclusion,
  /// One frame rolled by 6-25 deg, the image disagreeing with the motion: held past, as a
  /// short occlusion.
  kPoseJump,
};

/// "impact", "controller-silent", "reply-cut", "line-noise", "port-closed", "xoff-held",
/// "drive-fault", "drive-timeout", "unreadable-frame", "short-occlusion", "long-occlusion",
/// "pose-jump".
std::string ToString(FaultKind kind);
/// "simulated", "scorbot".
std::string ToString(FaultedRobot robot);

/// The faults of `robot` (the Scorbot: the link's and the frames'; else the drive's and the
/// frames'), in the order runs take them in turn.
std::vector<FaultKind> FaultKindsFor(FaultedRobot robot);

struct FaultCampaignOptions {
  int runs = 1000;         ///< [1, 1000000]
  std::uint64_t seed = 1;  ///< of the moments and the faults' details
  /// The Scorbot simulator's simulated seconds per second, [0.01, 1000] (the link keeps the
  /// job's pace).
  double time_scale = 20.0;
  /// The runs' output folders, run_NNNN/; a run that passes is removed, a failed one kept
  /// with its console log (servo.log).
  std::string work_dir = "out/fault-campaign";
  /// Runs at once, [1, 64]: a run mostly waits on the link's pace, so more than the cores.
  int jobs = 4;

  /// Throws std::invalid_argument naming the option, its value and the violated constraint.
  void Check() const;
};

/// One run as the campaign asks the job for it.
struct FaultRunRequest {
  std::string output_dir;  ///< the run's outputs, and nothing else, go here; no window
  /// kScorbot: the Controller-A simulator's device, to be opened with XON/XOFF flow control.
  std::string controller_port;
  /// The campaign's hooks (on_started, on_robot, on_grab) for the loop.
  ServoLoopHooks hooks;
  /// kSimulated: wraps the driver the job opens; the loop drives the wrapper in its place.
  std::function<std::unique_ptr<Robot>(std::unique_ptr<Robot>)> wrap_driver;
};

/// The job the campaign runs again and again.
struct FaultCampaignSetup {
  FaultedRobot robot = FaultedRobot::kSimulated;
  /// kScorbot: the simulator each run talks to (the campaign sets its time_scale and logs its
  /// input).
  ScorbotSimOptions controller;
  /// Runs the servo job once as `request` asks, writing its outputs and its console lines to
  /// `log` (kept beside a failed run's outputs for the reader, not judged). Called from
  /// FaultCampaignOptions::jobs threads at once.
  std::function<ServoRunReport(const FaultRunRequest& request, std::ostream& log)> run;
  /// What is wrong with the files the job wrote into `dir` for the run `report` tells of
  /// ("": whole), as only the job knows its files; unset: the campaign checks the temporary
  /// files and the images alone.
  using OutputCheck = std::function<std::string(const std::string& dir, const ServoRunReport&)>;
  OutputCheck check_outputs;
  /// The job's servo.max_lost_frames: a short occlusion is well within it (the loop holds
  /// one frame more than the hand covers, finding the target again), a long one lasts.
  int max_lost_frames = 60;
};

struct FaultRun {
  int index = 0;
  FaultKind kind = FaultKind::kImpact;
  bool reached = false;  ///< the fault happened before the run ended
  double fault_at_s = std::numeric_limits<double>::quiet_NaN();  ///< after the run began
  ServoRunStatus status = ServoRunStatus::kError;
  std::string message;
  bool robot_stopped = false;     ///< the run says so, and nothing moves after it
  bool stop_unconfirmed = false;  ///< the report says the stop could not be sent
  /// From the fault to the first stop command the robot received after it; NaN: none.
  double fault_to_stop_ms = std::numeric_limits<double>::quiet_NaN();
  int moves_after_stop = 0;  ///< motion commands the robot received after that stop
  /// Frame faults: the frames spoiled, and the motion commands the robot received while the
  /// loop had to hold (see the file comment).
  int spoiled_frames = 0;
  int moves_while_held = 0;
  bool outputs_whole = true;  ///< no temporary file, images decode, one CSV row an iteration
  double final_true_translation_mm = std::numeric_limits<double>::quiet_NaN();
  double final_true_rotation_deg = std::numeric_limits<double>::quiet_NaN();
  std::vector<std::string> problems;  ///< the rules above it broke; empty: it passed
};

struct FaultCampaignReport {
  FaultCampaignOptions options;
  FaultedRobot robot = FaultedRobot::kSimulated;
  double fault_free_s = 0;  ///< the fault-free run's duration
  double fault_free_translation_mm = 0, fault_free_rotation_deg = 0;  ///< its true final error
  std::vector<FaultRun> runs;
  int failed() const;
};

/// Runs the campaign on `setup`'s job. Throws std::runtime_error when the fault-free run does
/// not converge.
FaultCampaignReport RunFaultCampaign(
    const FaultCampaignSetup& setup, const FaultCampaignOptions& options,
    const std::function<void(int done, int total)>& progress = nullptr);

/// The campaign per fault as a Markdown table (runs, reached, stopped with the reason printed,
/// stop not confirmed and said so, converged on the goal, motion while held, motion after the
/// stop, fault to stop command median / max, outputs whole, failed), then each failed run and
/// its problems.
std::string FaultCampaignTable(const FaultCampaignReport& report);
/// The campaign as JSON: the options, the fault-free run, every run.
std::string FaultCampaignJson(const FaultCampaignReport& report);

}  // namespace oal
