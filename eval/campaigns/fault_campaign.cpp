#include "eval/campaigns/fault_campaign.h"

#include <visp3/core/vpMath.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <random>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <utility>

#include "base/check.h"
#include "base/statistics.h"
#include "robots/forwarding_robot.h"
#include "robots/scorbot_controller_sim.h"

namespace oal {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// The fault's moment: uniform over this much of a fault-free run.
constexpr double kMomentFraction = 0.85;
// Tries of a run whose fault came too late, the moment halved each time.
constexpr int kAttempts = 4;
// A run the fault did not stop must end this near the goal beyond where a fault-free run
// ends (the simulation's truth).
constexpr double kToleratedExtraMm = 2.0;
constexpr double kToleratedExtraDeg = 0.5;

// A motion or stop command the robot received, and when.
struct Command {
  Clock::time_point at;
  bool stop = false;  ///< else a motion
};

// The calls a wrapped driver received; written by the loop's thread, read after the run.
class CommandLog {
 public:
  void Add(bool stop) {
    std::lock_guard<std::mutex> lock(mutex_);
    commands_.push_back({Clock::now(), stop});
  }
  std::vector<Command> commands() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return commands_;
  }

 private:
  mutable std::mutex mutex_;
  std::vector<Command> commands_;
};

// The simulated robot's drive faults, switched on by the campaign's timer thread.
enum class DriveFault { kNone, kFails, kSilent };

// The simulated robot's driver seen through a wrapper that logs its motion and stop calls and,
// once the campaign switches a fault on, fails them as a broken drive would.
class TappedRobot final : public ForwardingRobot {
 public:
  TappedRobot(std::unique_ptr<Robot> inner, std::shared_ptr<CommandLog> log,
              std::shared_ptr<std::atomic<DriveFault>> fault)
      : ForwardingRobot(std::move(inner)), log_(std::move(log)), fault_(std::move(fault)) {}

  RobotResult Enable() override {
    const std::optional<RobotResult> fault = Fault();
    return fault ? *fault : inner().Enable();
  }
  RobotResult Disable() noexcept override {
    log_->Add(true);
    return fault_->load() == DriveFault::kSilent ? *Fault() : inner().Disable();
  }
  RobotResult Stop() noexcept override {
    log_->Add(true);
    return fault_->load() == DriveFault::kSilent ? *Fault() : inner().Stop();
  }
  RobotPose GetPosition(RobotFrame frame) override {
    const std::optional<RobotResult> fault = Fault();
    return fault ? RobotPose{*fault, vpHomogeneousMatrix()} : inner().GetPosition(frame);
  }
  RobotResult StartMove(RobotFrame frame, const vpHomogeneousMatrix& target) override {
    log_->Add(false);
    const std::optional<RobotResult> fault = Fault();
    return fault ? *fault : inner().StartMove(frame, target);
  }
  MoveProgress PollMove() override {
    const std::optional<RobotResult> fault = Fault();
    return fault ? MoveProgress{*fault, false} : inner().PollMove();
  }
  RobotResult SetVelocity(RobotFrame frame, const vpColVector& v) override {
    if (v.frobeniusNorm() > 0.0) log_->Add(false);  // a zero twist holds the robot: no motion
    const std::optional<RobotResult> fault = Fault();
    return fault ? *fault : inner().SetVelocity(frame, v);
  }

 private:
  std::optional<RobotResult> Fault() const {
    switch (fault_->load()) {
      case DriveFault::kFails:
        return RobotResult::Fail(RobotStatus::kError, "drive fault (injected)");
      case DriveFault::kSilent:
        return RobotResult::Fail(RobotStatus::kTimeout, "the drive does not answer (injected)");
      case DriveFault::kNone:
        break;
    }
    return std::nullopt;
  }

  std::shared_ptr<CommandLog> log_;
  std::shared_ptr<std::atomic<DriveFault>> fault_;
};

// Calls `fire` once, `delay_s` after Start(), again every 2 ms while it returns false (an
// impact waits for the arm to move); never after Cancel().
class FaultTimer {
 public:
  explicit FaultTimer(std::function<bool()> fire) : fire_(std::move(fire)) {}
  ~FaultTimer() { Cancel(); }
  FaultTimer(const FaultTimer&) = delete;
  FaultTimer& operator=(const FaultTimer&) = delete;

  void Start(double delay_s) {
    thread_ = std::thread([this, delay_s] { Run(delay_s); });
  }
  void Cancel() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      cancelled_ = true;
    }
    wake_.notify_all();
    if (thread_.joinable()) thread_.join();
  }

 private:
  void Run(double delay_s) {
    std::unique_lock<std::mutex> lock(mutex_);
    const auto at = Clock::now() + std::chrono::microseconds(static_cast<long long>(delay_s * 1e6));
    if (wake_.wait_until(lock, at, [this] { return cancelled_; })) return;
    while (!cancelled_) {
      lock.unlock();
      const bool done = fire_();
      lock.lock();
      if (done) return;
      wake_.wait_for(lock, std::chrono::milliseconds(2), [this] { return cancelled_; });
    }
  }

  std::function<bool()> fire_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool cancelled_ = false;
  std::thread thread_;
};

// One run's fault: what, when, and its details, drawn from the seed.
struct FaultPlan {
  FaultKind kind = FaultKind::kImpact;
  double delay_s = 0;                  ///< after the run began
  int axis = 1;                        ///< impact
  std::string noise;                   ///< line noise
  cv::Point2d blob_centre, blob_axes;  ///< occlusion, fractions of the image
  double roll_deg = 0;                 ///< pose jump
  int frames = 1;                      ///< frames spoiled (a long occlusion: all from then on)
};

// Frame faults the loop must hold past, and the one it must stop at.
bool HeldPast(FaultKind kind) {
  return kind == FaultKind::kShortOcclusion || kind == FaultKind::kPoseJump;
}

FaultPlan PlanFault(FaultKind kind, double fault_free_s, int max_lost_frames, std::uint64_t seed,
                    int index) {
  std::mt19937_64 random(seed * 1000003ULL + static_cast<std::uint64_t>(index));
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  FaultPlan plan;
  plan.kind = kind;
  plan.delay_s = unit(random) * kMomentFraction * fault_free_s;
  plan.axis = 1 + static_cast<int>(random() % 5);
  const int noise_bytes = 1 + static_cast<int>(random() % 16);
  for (int i = 0; i < noise_bytes; ++i) plan.noise.push_back(static_cast<char>(random() % 256));
  plan.blob_centre = {0.4 + 0.2 * unit(random), 0.4 + 0.2 * unit(random)};
  // A hand close to the lens, over the whole view: one the tracker might see past would not
  // tell whether the loop holds.
  plan.blob_axes = {0.9 + 0.2 * unit(random), 0.9 + 0.2 * unit(random)};
  plan.roll_deg = (6.0 + 19.0 * unit(random)) * (random() % 2 == 0 ? 1.0 : -1.0);
  // A short hand: 1 to 10 frames, at most half the frames the loop holds for.
  const int short_frames = std::clamp(max_lost_frames / 2, 1, 10);
  plan.frames = 1 + static_cast<int>(random() % static_cast<unsigned>(short_frames));
  if (kind == FaultKind::kLongOcclusion) plan.frames = std::numeric_limits<int>::max();
  if (kind != FaultKind::kShortOcclusion && kind != FaultKind::kLongOcclusion) plan.frames = 1;
  return plan;
}

// The frame as the fault spoils it (the frame may be a view of the renderer's buffer: the
// spoiled frame is a new image).
void SpoilFrame(const FaultPlan& plan, cv::Mat* gray) {
  const cv::Size size = gray->size();
  if (plan.kind == FaultKind::kUnreadableFrame) {
    gray->release();
  } else if (plan.kind == FaultKind::kShortOcclusion || plan.kind == FaultKind::kLongOcclusion) {
    cv::Mat occluded = gray->clone();
    cv::ellipse(occluded,
                cv::Point(static_cast<int>(plan.blob_centre.x * size.width),
                          static_cast<int>(plan.blob_centre.y * size.height)),
                cv::Size(static_cast<int>(plan.blob_axes.x * size.width),
                         static_cast<int>(plan.blob_axes.y * size.height)),
                0.0, 0.0, 360.0, cv::Scalar(35), cv::FILLED);
    *gray = occluded;
  } else if (plan.kind == FaultKind::kPoseJump) {
    const cv::Point2f centre(0.5f * static_cast<float>(size.width - 1),
                             0.5f * static_cast<float>(size.height - 1));
    cv::Mat rolled;
    cv::warpAffine(*gray, rolled, cv::getRotationMatrix2D(centre, plan.roll_deg, 1.0), size,
                   cv::INTER_LINEAR, cv::BORDER_REPLICATE);
    *gray = rolled;
  }
}

// What one run did, seen from outside the loop.
struct Outcome {
  ServoRunReport report;
  std::string log;
  std::vector<Command> commands;
  bool robot_moving_at_end = false;  ///< the Scorbot simulator's arm
  Clock::time_point started, ended;
  std::optional<Clock::time_point> fault_at;  ///< none: the run ended first
  std::optional<Clock::time_point> released;  ///< the loop let go of the robot (final stop)
  /// When each frame was taken (the loop's thread writes it, read after the run), and the
  /// iterations of the first and last frame spoiled.
  std::vector<std::pair<int, Clock::time_point>> grabs;
  int first_spoiled = -1, last_spoiled = -1;
};

// The Scorbot's commands as the controller received them: MOVE lines and Ctrl-A.
std::vector<Command> WireCommands(const std::vector<HeardLine>& heard) {
  std::vector<Command> commands;
  for (const HeardLine& line : heard) {
    std::string upper = line.text;
    for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    if (line.text == "^A") {
      commands.push_back({line.at, true});
    } else if (upper.rfind("MOVE", 0) == 0) {
      commands.push_back({line.at, false});
    }
  }
  return commands;
}

Outcome RunOnce(const FaultCampaignSetup& setup, const FaultCampaignOptions& options,
                const std::optional<FaultPlan>& plan, const fs::path& dir) {
  FaultRunRequest request;
  request.output_dir = dir.string();
  const bool scorbot = setup.robot == FaultedRobot::kScorbot;
  std::unique_ptr<ScorbotControllerSim> sim;
  if (scorbot) {
    ScorbotSimOptions sim_options = setup.controller;
    sim_options.time_scale = options.time_scale;
    sim_options.log_input = true;
    sim = std::make_unique<ScorbotControllerSim>(sim_options);
    sim->Start();
    request.controller_port = sim->DevicePath();
  }
  auto commands = std::make_shared<CommandLog>();
  auto drive = std::make_shared<std::atomic<DriveFault>>(DriveFault::kNone);
  std::atomic<Clock::rep> fault_at{0};  // since the clock's epoch; 0: not yet
  std::atomic<int> frames_armed{0};     // frames still to spoil
  const auto mark = [&fault_at] { fault_at.store(Clock::now().time_since_epoch().count()); };
  FaultTimer timer([&]() -> bool {
    switch (plan->kind) {
      case FaultKind::kImpact:
        if (!sim->moving()) return false;
        sim->InjectImpactNow(plan->axis);
        break;
      case FaultKind::kControllerSilent:
        sim->SetSilent(true);
        break;
      case FaultKind::kReplyCut:
        sim->InjectCutReply();
        break;
      case FaultKind::kLineNoise:
        sim->InjectNoise(plan->noise);
        break;
      case FaultKind::kPortClosed:
        sim->Stop();
        break;
      case FaultKind::kXoffHeld:
        sim->SendXoff();
        break;
      case FaultKind::kDriveFault:
        drive->store(DriveFault::kFails);
        break;
      case FaultKind::kDriveTimeout:
        drive->store(DriveFault::kSilent);
        break;
      case FaultKind::kUnreadableFrame:
      case FaultKind::kShortOcclusion:
      case FaultKind::kLongOcclusion:
      case FaultKind::kPoseJump:
        frames_armed = plan->frames;  // the next frames take it
        return true;
    }
    mark();
    return true;
  });

  Outcome outcome;
  ServoLoopHooks& hooks = request.hooks;
  hooks.on_started = [&] {
    outcome.started = Clock::now();
    if (plan) timer.Start(plan->delay_s);
  };
  // The loop lets go of the robot just before its final stop: a fault after that would come
  // after the run, so none fires any more.
  hooks.on_robot = [&](SafeRobot* robot) {
    if (robot != nullptr || outcome.released) return;
    timer.Cancel();
    outcome.released = Clock::now();
  };
  hooks.on_grab = [&](int iteration, cv::Mat* gray) {
    outcome.grabs.emplace_back(iteration, Clock::now());
    int left = frames_armed.load();
    while (left > 0 && !frames_armed.compare_exchange_weak(left, left - 1)) {
    }
    if (left <= 0) return;
    SpoilFrame(*plan, gray);
    if (outcome.first_spoiled < 0) {
      outcome.first_spoiled = iteration;
      mark();
    }
    outcome.last_spoiled = iteration;
  };
  if (!scorbot) {
    request.wrap_driver = [&](std::unique_ptr<Robot> driver) -> std::unique_ptr<Robot> {
      return std::make_unique<TappedRobot>(std::move(driver), commands, drive);
    };
  }
  std::ostringstream log;
  outcome.report = setup.run(request, log);
  outcome.ended = Clock::now();
  timer.Cancel();
  outcome.log = log.str();
  if (const Clock::rep at = fault_at.load(); at != 0) {
    outcome.fault_at = Clock::time_point(Clock::duration(at));
  }
  if (sim) {
    outcome.robot_moving_at_end = sim->moving();
    outcome.commands = WireCommands(sim->heard());
  } else {
    outcome.commands = commands->commands();
  }
  return outcome;
}

// "" when `dir` holds whole files only: no temporary file, every image decodes, and what the
// job says of its own files (`check_job`, when given); else what is wrong.
std::string CheckOutputs(const fs::path& dir, const ServoRunReport& report,
                         const FaultCampaignSetup::OutputCheck& check_job) {
  if (!fs::exists(dir)) return report.started ? "the output folder is missing" : "";
  for (const fs::directory_entry& entry : fs::recursive_directory_iterator(dir)) {
    const fs::path& path = entry.path();
    if (path.filename().string().find(".tmp-") != std::string::npos) {
      return "a temporary file was left: " + path.string();
    }
    if (path.extension() == ".png" && cv::imread(path.string(), cv::IMREAD_UNCHANGED).empty()) {
      return "an image that does not decode: " + path.string();
    }
  }
  return check_job ? check_job(dir.string(), report) : "";
}

bool TakesTheLink(FaultKind kind) {
  return kind == FaultKind::kPortClosed || kind == FaultKind::kControllerSilent ||
         kind == FaultKind::kDriveTimeout;
}

// The true final error of a run (the last row's).
void FinalTrueError(const ServoRunReport& report, double* mm, double* deg) {
  if (report.iterations.empty()) return;
  *mm = report.iterations.back().true_translation_error_mm;
  *deg = report.iterations.back().true_rotation_error_deg;
}

// A frame fault the loop must hold past: no motion from its first spoiled frame until the
// second frame after its last (found again, then confirmed), and the run converged; a long
// occlusion: no motion from its first frame on, and the run stopped with target-lost.
void JudgeHold(const Outcome& outcome, const FaultPlan& plan, FaultRun* run) {
  const bool held_past = HeldPast(plan.kind),
             long_occlusion = plan.kind == FaultKind::kLongOcclusion;
  if ((!held_past && !long_occlusion) || outcome.first_spoiled < 0) return;
  run->spoiled_frames = outcome.last_spoiled - outcome.first_spoiled + 1;
  std::optional<Clock::time_point> from, until;
  for (const auto& [iteration, at] : outcome.grabs) {
    if (iteration == outcome.first_spoiled) from = at;
    if (held_past && iteration == outcome.last_spoiled + 2) until = at;
  }
  for (const Command& command : outcome.commands) {
    run->moves_while_held +=
        !command.stop && from && command.at >= *from && (!until || command.at < *until);
  }
  std::vector<std::string>& problems = run->problems;
  const std::string fault = ToString(plan.kind) + " of " + std::to_string(run->spoiled_frames) +
                            (run->spoiled_frames == 1 ? " frame" : " frames");
  if (run->moves_while_held > 0) {
    problems.push_back(std::to_string(run->moves_while_held) +
                       " motion command(s) while the loop " + "had to hold (" + fault + ")");
  }
  const ServoRunStatus expected =
      held_past ? ServoRunStatus::kConverged : ServoRunStatus::kTargetLost;
  if (outcome.report.status != expected) {
    problems.push_back("a " + fault + " should end " + ToString(expected) + ", not " +
                       ToString(outcome.report.status));
  }
}

FaultRun Judge(const Outcome& outcome, const FaultPlan& plan, const fs::path& dir,
               const FaultCampaignReport& campaign, const FaultCampaignSetup& setup) {
  FaultRun run;
  run.kind = plan.kind;
  const ServoRunReport& report = outcome.report;
  run.status = report.status;
  run.message = report.message;
  FinalTrueError(report, &run.final_true_translation_mm, &run.final_true_rotation_deg);
  run.reached = outcome.fault_at.has_value();
  if (!run.reached) return run;
  const Clock::time_point fault_at = *outcome.fault_at;
  run.fault_at_s = std::chrono::duration<double>(fault_at - outcome.started).count();
  std::optional<Clock::time_point> stop_at;
  for (const Command& command : outcome.commands) {
    if (!stop_at && command.stop && command.at >= fault_at) {
      stop_at = command.at;
    } else if (stop_at && !command.stop && command.at > *stop_at) {
      ++run.moves_after_stop;
    }
  }
  if (stop_at) {
    run.fault_to_stop_ms = std::chrono::duration<double, std::milli>(*stop_at - fault_at).count();
  }
  const bool last_is_stop = !outcome.commands.empty() && outcome.commands.back().stop;
  // The loop's report: the stop was sent and confirmed, or it says why not.
  run.stop_unconfirmed = report.started && !report.robot_stopped;
  run.robot_stopped = report.robot_stopped && !outcome.robot_moving_at_end &&
                      (outcome.commands.empty() || last_is_stop);

  std::vector<std::string>& problems = run.problems;
  if (report.message.empty()) problems.push_back("the run ended without its reason");
  if (run.stop_unconfirmed) {
    if (!TakesTheLink(plan.kind)) {
      problems.push_back("the stop could not be sent though the fault leaves the link up");
    }
  } else if (!run.robot_stopped) {
    problems.push_back("the run ended without the robot stopped");
  }
  if (!stop_at && plan.kind != FaultKind::kPortClosed) {
    problems.push_back("no stop command reached the robot after the fault");
  }
  if (run.moves_after_stop > 0) {
    problems.push_back(std::to_string(run.moves_after_stop) +
                       " motion command(s) after the stop command");
  }
  JudgeHold(outcome, plan, &run);
  if (report.status == ServoRunStatus::kConverged &&
      (!(run.final_true_translation_mm <= campaign.fault_free_translation_mm + kToleratedExtraMm) ||
       !(run.final_true_rotation_deg <= campaign.fault_free_rotation_deg + kToleratedExtraDeg))) {
    std::ostringstream text;
    text << "converged " << run.final_true_translation_mm << " mm, " << run.final_true_rotation_deg
         << " deg from the goal (the fault-free run: " << campaign.fault_free_translation_mm
         << " mm, " << campaign.fault_free_rotation_deg << " deg)";
    problems.push_back(text.str());
  }
  if (const std::string outputs = CheckOutputs(dir, report, setup.check_outputs);
      !outputs.empty()) {
    run.outputs_whole = false;
    problems.push_back(outputs);
  }
  return run;
}

}  // namespace

std::string ToString(FaultKind kind) {
  switch (kind) {
    case FaultKind::kImpact:
      return "impact";
    case FaultKind::kControllerSilent:
      return "controller-silent";
    case FaultKind::kReplyCut:
      return "reply-cut";
    case FaultKind::kLineNoise:
      return "line-noise";
    case FaultKind::kPortClosed:
      return "port-closed";
    case FaultKind::kXoffHeld:
      return "xoff-held";
    case FaultKind::kDriveFault:
      return "drive-fault";
    case FaultKind::kDriveTimeout:
      return "drive-timeout";
    case FaultKind::kUnreadableFrame:
      return "unreadable-frame";
    case FaultKind::kShortOcclusion:
      return "short-occlusion";
    case FaultKind::kLongOcclusion:
      return "long-occlusion";
    case FaultKind::kPoseJump:
      return "pose-jump";
  }
  return "impact";
}

std::string ToString(FaultedRobot robot) {
  return robot == FaultedRobot::kScorbot ? "scorbot" : "simulated";
}

std::vector<FaultKind> FaultKindsFor(FaultedRobot robot) {
  const std::vector<FaultKind> frames = {FaultKind::kUnreadableFrame, FaultKind::kShortOcclusion,
                                         FaultKind::kLongOcclusion, FaultKind::kPoseJump};
  std::vector<FaultKind> kinds;
  if (robot == FaultedRobot::kScorbot) {
    kinds = {FaultKind::kImpact,    FaultKind::kControllerSilent, FaultKind::kReplyCut,
             FaultKind::kLineNoise, FaultKind::kPortClosed,       FaultKind::kXoffHeld};
  } else {
    kinds = {FaultKind::kDriveFault, FaultKind::kDriveTimeout};
  }
  kinds.insert(kinds.end(), frames.begin(), frames.end());
  return kinds;
}

void FaultCampaignOptions::Check() const {
  RequireOption(runs >= 1 && runs <= 1000000, "FaultCampaignOptions::runs", runs,
                "1 <= runs <= 1000000");
  RequireOption(time_scale >= 0.01 && time_scale <= 1000.0, "FaultCampaignOptions::time_scale",
                time_scale, "0.01 <= time_scale <= 1000");
  RequireOption(jobs >= 1 && jobs <= 64, "FaultCampaignOptions::jobs", jobs, "1 <= jobs <= 64");
  RequireOption(!work_dir.empty(), "FaultCampaignOptions::work_dir", "''", "a folder is given");
}

int FaultCampaignReport::failed() const {
  int count = 0;
  for (const FaultRun& run : runs) count += !run.problems.empty();
  return count;
}

FaultCampaignReport RunFaultCampaign(const FaultCampaignSetup& setup,
                                     const FaultCampaignOptions& options,
                                     const std::function<void(int, int)>& progress) {
  options.Check();
  if (!setup.run) throw std::invalid_argument("RunFaultCampaign: no servo job to run");
  FaultCampaignReport campaign;
  campaign.options = options;
  campaign.robot = setup.robot;
  const fs::path work = options.work_dir;
  fs::create_directories(work);

  const fs::path fault_free_dir = work / "fault-free";
  const Outcome fault_free = RunOnce(setup, options, std::nullopt, fault_free_dir);
  if (fault_free.report.status != ServoRunStatus::kConverged) {
    throw std::runtime_error(
        "the fault campaign needs a configuration whose run converges without a fault; it "
        "ended " +
        ToString(fault_free.report.status) + ": " + fault_free.report.message);
  }
  campaign.fault_free_s = std::chrono::duration<double>(
                              fault_free.released.value_or(fault_free.ended) - fault_free.started)
                              .count();
  FinalTrueError(fault_free.report, &campaign.fault_free_translation_mm,
                 &campaign.fault_free_rotation_deg);
  fs::remove_all(fault_free_dir);

  const std::vector<FaultKind> kinds = FaultKindsFor(setup.robot);
  const auto run_one = [&](int i) {
    FaultPlan plan = PlanFault(kinds[static_cast<std::size_t>(i) % kinds.size()],
                               campaign.fault_free_s, setup.max_lost_frames, options.seed, i);
    std::ostringstream name;
    name << "run_" << std::setw(4) << std::setfill('0') << i;
    const fs::path dir = work / name.str();
    // A run can end before its fault's moment (faster than the fault-free one): run it again
    // with the moment halved.
    Outcome outcome;
    for (int attempt = 1;; ++attempt) {
      fs::remove_all(dir);  // an earlier attempt's, or an earlier campaign's run of this number
      outcome = RunOnce(setup, options, plan, dir);
      if (outcome.fault_at || attempt == kAttempts) break;
      plan.delay_s /= 2;
    }
    FaultRun run = Judge(outcome, plan, dir, campaign, setup);
    run.index = i;
    if (run.problems.empty()) {
      fs::remove_all(dir);
    } else {
      fs::create_directories(dir);
      std::ofstream(dir / "servo.log") << outcome.log;
    }
    return run;
  };
  campaign.runs.resize(static_cast<std::size_t>(options.runs));
  std::atomic<int> next{0};
  std::mutex mutex;  // progress, done, error
  int done = 0;
  std::exception_ptr error;
  const auto worker = [&] {
    for (int i = next++; i < options.runs; i = next++) {
      try {
        campaign.runs[static_cast<std::size_t>(i)] = run_one(i);
      } catch (...) {
        std::lock_guard<std::mutex> lock(mutex);
        if (!error) error = std::current_exception();
        next = options.runs;  // the others finish the run they are in, and stop
        return;
      }
      std::lock_guard<std::mutex> lock(mutex);
      ++done;
      if (progress) progress(done, options.runs);
    }
  };
  std::vector<std::thread> workers;
  for (int j = 0; j < std::min(options.jobs, options.runs); ++j) workers.emplace_back(worker);
  for (std::thread& thread : workers) thread.join();
  if (error) std::rethrow_exception(error);
  return campaign;
}

std::string FaultCampaignTable(const FaultCampaignReport& report) {
  std::ostringstream out;
  out << "| fault | runs | reached | stopped, reason printed | stop not confirmed, said so | "
         "converged on the goal | motion while held | motion after the stop | fault to stop "
         "command median / max | outputs whole | failed |\n"
      << "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const FaultKind kind : FaultKindsFor(report.robot)) {
    int runs = 0, reached = 0, stopped = 0, unconfirmed = 0, converged = 0, moved = 0, whole = 0;
    int moved_held = 0;
    int failed = 0;
    std::vector<double> stop_ms;
    for (const FaultRun& run : report.runs) {
      if (run.kind != kind) continue;
      ++runs;
      failed += !run.problems.empty();
      if (!run.reached) continue;
      ++reached;
      stopped += run.robot_stopped && !run.stop_unconfirmed;
      unconfirmed += run.stop_unconfirmed;
      converged += run.status == ServoRunStatus::kConverged;
      moved += run.moves_after_stop > 0;
      moved_held += run.moves_while_held > 0;
      whole += run.outputs_whole;
      if (std::isfinite(run.fault_to_stop_ms)) stop_ms.push_back(run.fault_to_stop_ms);
    }
    if (runs == 0) continue;
    out << "| " << ToString(kind) << " | " << runs << " | " << reached << " | " << stopped << " | "
        << unconfirmed << " | " << converged << " | " << moved_held << " | " << moved << " | "
        << std::fixed << std::setprecision(0);
    if (stop_ms.empty()) {
      out << "-";
    } else {
      out << Quantile(stop_ms, 0.5) << " / " << Quantile(stop_ms, 1.0) << " ms";
    }
    out << std::defaultfloat << " | " << whole << " | " << failed << " |\n";
  }
  for (const FaultRun& run : report.runs) {
    if (run.problems.empty()) continue;
    out << "- run " << run.index << " (" << ToString(run.kind) << " at " << std::setprecision(3)
        << run.fault_at_s << " s): " << ToString(run.status) << ": " << run.message << "\n";
    for (const std::string& problem : run.problems) out << "  - " << problem << "\n";
  }
  return out.str();
}

std::string FaultCampaignJson(const FaultCampaignReport& report) {
  const auto number = [](double value) -> nlohmann::json {
    return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json();
  };
  nlohmann::json runs = nlohmann::json::array();
  for (const FaultRun& run : report.runs) {
    runs.push_back({{"run", run.index},
                    {"fault", ToString(run.kind)},
                    {"reached", run.reached},
                    {"fault_at_s", number(run.fault_at_s)},
                    {"status", ToString(run.status)},
                    {"message", run.message},
                    {"robot_stopped", run.robot_stopped},
                    {"stop_unconfirmed", run.stop_unconfirmed},
                    {"fault_to_stop_ms", number(run.fault_to_stop_ms)},
                    {"moves_after_stop", run.moves_after_stop},
                    {"spoiled_frames", run.spoiled_frames},
                    {"moves_while_held", run.moves_while_held},
                    {"outputs_whole", run.outputs_whole},
                    {"final_true_translation_error_mm", number(run.final_true_translation_mm)},
                    {"final_true_rotation_error_deg", number(run.final_true_rotation_deg)},
                    {"problems", run.problems}});
  }
  const FaultCampaignOptions& o = report.options;
  return nlohmann::json{{"options",
                         {{"faults", o.runs},
                          {"seed", o.seed},
                          {"time_scale", o.time_scale},
                          {"jobs", o.jobs},
                          {"work_dir", o.work_dir}}},
                        {"robot", ToString(report.robot)},
                        {"fault_free_run_s", report.fault_free_s},
                        {"fault_free_true_translation_error_mm", report.fault_free_translation_mm},
                        {"fault_free_true_rotation_error_deg", report.fault_free_rotation_deg},
                        {"failed", report.failed()},
                        {"runs", runs}}
             .dump(2) +
         "\n";
}

}  // namespace oal
