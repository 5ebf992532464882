// The servo loop as a library: a setup of plain values, frames rendered in the loop or read
// from files, the simulated camera as the robot; no configuration file, no command line.
#include "loop/servo_loop.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "io/image_source.h"
#include "loop/frame_source.h"
#include "robots/simulated_camera.h"
#include "scene/scene.h"
#include "tests/test_util.h"

namespace oal {
namespace {

using ::testing::HasSubstr;

// The A3 sheet at the world's origin, the goal 0.5 m in front of it, the start 0.6 m away,
// a little to the side and turned.
ServoSetup SheetSetup(ServoMode mode) {
  ServoSetup setup;
  setup.target = FourLineA3Target();
  const RenderOptions render;
  setup.camera = render.camera;
  setup.width = render.width;
  setup.height = render.height;
  setup.loop.law.mode = mode;
  setup.cdMo = vpHomogeneousMatrix(0.0, 0.0, 0.5, 0.0, 0.0, 0.0);
  return setup;
}

const vpHomogeneousMatrix kStartcMo(0.03, -0.02, 0.6, vpMath::rad(4.0), vpMath::rad(-3.0),
                                    vpMath::rad(25.0));

SimulatedCameraOptions StartingAt(const vpHomogeneousMatrix& cMo, const vpHomogeneousMatrix& wMo) {
  SimulatedCameraOptions options;
  options.wMc = wMo * cMo.inverse();
  return options;
}

// Looking away: the sheet 0.8 m to the side, out of the view.
SimulatedCameraOptions LookingAway(const vpHomogeneousMatrix& wMo) {
  return StartingAt(vpHomogeneousMatrix(0.8, 0.0, 0.6, 0.0, 0.0, 0.0), wMo);
}

TEST(ServoLoopOptions, EachLawHasItsOwnIterationLimit) {
  ServoLoopOptions loop;
  loop.law.mode = ServoMode::kExponential;
  EXPECT_EQ(loop.IterationLimit(false), 30);
  loop.law.mode = ServoMode::kPointAndGo;
  EXPECT_EQ(loop.IterationLimit(false), 30);
  loop.law.mode = ServoMode::kVelocity;
  EXPECT_EQ(loop.IterationLimit(false), 300);
  EXPECT_GT(loop.IterationLimit(true), 1000000) << "a replay runs to its end";
  loop.max_iterations = 7;
  EXPECT_EQ(loop.IterationLimit(false), 7);
  EXPECT_EQ(loop.IterationLimit(true), 7);
}

TEST(ServoLoopOptions, CheckNamesTheField) {
  const std::vector<std::pair<std::function<void(ServoLoopOptions*)>, const char*>> bad = {
      {[](ServoLoopOptions* loop) { loop->max_step_deg = 200.0; },
       "ServoLoopOptions::max_step_deg = 200"},
      {[](ServoLoopOptions* loop) { loop->max_lost_s = -1.0; },
       "ServoLoopOptions::max_lost_s = -1"},
      {[](ServoLoopOptions* loop) { loop->max_lost_frames = -1; },
       "ServoLoopOptions::max_lost_frames = -1"},
  };
  for (const auto& [set, named] : bad) {
    ServoLoopOptions loop;
    set(&loop);
    try {
      loop.Check();
      FAIL() << named << " accepted";
    } catch (const std::invalid_argument& error) {
      EXPECT_THAT(error.what(), HasSubstr(named));
    }
  }
}

TEST(RunServoLoop, EachPositionLawReachesTheGoalOnTheRenderedSheet) {
  for (const ServoMode mode : {ServoMode::kPointAndGo, ServoMode::kExponential}) {
    const ServoSetup setup = SheetSetup(mode);
    SimulatedCamera robot(StartingAt(kStartcMo, setup.wMo));
    RenderedFrames frames(setup.target, RenderOptions());
    std::ostringstream log;
    const ServoRunReport report = RunServoLoop(setup, frames, robot, log);
    ASSERT_EQ(report.status, ServoRunStatus::kConverged)
        << ToString(mode) << ": " << report.message;
    EXPECT_TRUE(report.robot_stopped);
    EXPECT_TRUE(report.started);
    // The truth: where the camera really is against the goal.
    const vpHomogeneousMatrix true_cMo = report.final_wMc.inverse() * setup.wMo;
    const vpHomogeneousMatrix error = setup.cdMo * true_cMo.inverse();
    EXPECT_LT(error.getTranslationVector().frobeniusNorm(), 2e-3) << ToString(mode);
    // The rendered frames know the truth: the table shows it.
    EXPECT_THAT(log.str(), HasSubstr("true mm"));
    EXPECT_LT(report.iterations.back().true_translation_error_mm, 2.0);
  }
}

TEST(RunServoLoop, ATargetOutOfViewStopsTheRunAndTheRobotNeverMoves) {
  ServoSetup setup = SheetSetup(ServoMode::kPointAndGo);
  setup.loop.max_lost_frames = 2;
  const SimulatedCameraOptions away = LookingAway(setup.wMo);
  SimulatedCamera robot(away);
  const vpHomogeneousMatrix start = away.wMc;
  RenderedFrames frames(setup.target, RenderOptions());
  std::ostringstream log;
  const ServoRunReport report = RunServoLoop(setup, frames, robot, log);
  EXPECT_EQ(report.status, ServoRunStatus::kTargetLost) << report.message;
  EXPECT_THAT(report.message, HasSubstr("target lost: held 3 frames"));
  EXPECT_EQ(report.moves, 0);
  ASSERT_EQ(report.iterations.size(), 3u);
  EXPECT_THAT(report.iterations[0].held, HasSubstr("no pose: "));
  const vpHomogeneousMatrix end = robot.GetPosition(RobotFrame::kCamera).pose;
  EXPECT_LT((end.getTranslationVector() - start.getTranslationVector()).frobeniusNorm(), 1e-12);
}

// The hold's time limit runs on the simulated camera's clock (a frame a sampling period, 40 ms):
// 0.1 s is passed at the fourth frame held, whatever the machine's speed.
TEST(RunServoLoop, AHoldStopsAfterMaxLostSecondsOfTheCamerasClock) {
  ServoSetup setup = SheetSetup(ServoMode::kExponential);
  setup.loop.max_lost_s = 0.1;
  const SimulatedCameraOptions away = LookingAway(setup.wMo);
  SimulatedCamera robot(away);
  RenderedFrames frames(setup.target, RenderOptions());
  std::ostringstream log;
  const ServoRunReport report = RunServoLoop(setup, frames, robot, log);
  EXPECT_EQ(report.status, ServoRunStatus::kTargetLost) << report.message;
  EXPECT_THAT(report.message, HasSubstr("target lost: held 4 frames (0.12 s)"));
  EXPECT_EQ(report.moves, 0);
}

TEST(RunServoLoop, AnOpenLoopReplayComputesTheLawAndNeverMovesTheRobot) {
  const test::TestDir dir;
  const ServoSetup goal_setup = SheetSetup(ServoMode::kPointAndGo);
  SceneRenderer renderer(goal_setup.target, RenderOptions());
  for (int k = 0; k < 3; ++k) {
    const RenderedFrame frame = renderer.Render(kStartcMo, 10 + static_cast<std::uint64_t>(k));
    const cv::Mat gray(static_cast<int>(frame.image.getHeight()),
                       static_cast<int>(frame.image.getWidth()), CV_8UC1, frame.image.bitmap);
    ASSERT_TRUE(cv::imwrite(dir / ("frame_000" + std::to_string(k) + ".png"), gray));
  }
  ServoSetup setup = goal_setup;
  setup.open_loop = true;
  SimulatedCamera robot;
  RecordedFrames frames(OpenImageSource(dir.path().string()));
  std::ostringstream log;
  const ServoRunReport report = RunServoLoop(setup, frames, robot, log);
  EXPECT_EQ(report.status, ServoRunStatus::kEndOfInput) << report.message;
  EXPECT_EQ(report.moves, 0);
  ASSERT_EQ(report.iterations.size(), 3u);
  for (const ServoIteration& row : report.iterations) {
    // The law saw the pose: 0.1 m and 25 deg from the goal; the truth is not known.
    EXPECT_NEAR(row.translation_error_mm,
                1e3 * (setup.cdMo * kStartcMo.inverse()).getTranslationVector().frobeniusNorm(),
                1.0);
    EXPECT_TRUE(std::isnan(row.true_translation_error_mm));
  }
  EXPECT_THAT(log.str(), HasSubstr("open loop, the robot is not moved"));
  EXPECT_THAT(log.str(), ::testing::Not(HasSubstr("true mm")));
}

TEST(RecordedFrames, AnUnreadableFrameIsReportedWhereItIsTakenNotAsTheEnd) {
  const test::TestDir dir;
  const cv::Mat grey(48, 64, CV_8UC1, cv::Scalar(128));
  ASSERT_TRUE(cv::imwrite(dir / "frame_0000.png", grey));
  {
    std::ofstream broken(dir / "frame_0001.png");
    broken << "not a PNG";
  }
  RecordedFrames frames(OpenImageSource(dir.path().string()));
  cv::Mat gray;
  ASSERT_TRUE(frames.Grab(Capture{}, &gray));
  EXPECT_EQ(gray.cols, 64);
  EXPECT_FALSE(frames.AtEnd()) << "an unreadable frame is not the end";
  Capture second;
  second.iteration = 1;
  EXPECT_THROW(frames.Grab(second, &gray), std::runtime_error);
}

// The simulated camera's lived-in episodes: drawn on its clock, the same for the same time
// whatever was asked before, each held through its length; a hand in every episode changes
// the frame; its own motion over the exposure smears it, more the faster it moves.
TEST(RenderedFrames, EpisodesHoldTheirConditionsAndMotionSmearsTheFrame) {
  const ServoSetup setup = SheetSetup(ServoMode::kVelocity);
  SimulatedCameraScene scene;
  scene.lived_in.occluders.fraction = 1.0;
  scene.lived_in.occluders.kinds = {OccluderKind::kHand};
  scene.episode_s = {0.5, 0.5};
  scene.exposure_s = 0.02;
  RenderedFrames hands(setup.target, RenderOptions(), scene);
  RenderedFrames plain(setup.target, RenderOptions());
  Capture capture;
  capture.true_cMo = kStartcMo;
  const auto frame = [&](RenderedFrames& frames, double time_s) {
    capture.time_s = time_s;
    cv::Mat gray;
    EXPECT_TRUE(frames.Grab(capture, &gray));
    return gray.clone();
  };
  const cv::Mat bare = frame(plain, 0.0);
  const cv::Mat first = frame(hands, 0.1), later = frame(hands, 1.3);
  EXPECT_GT(cv::norm(first, bare, cv::NORM_L1), 1e5) << "a hand over the sheet";
  EXPECT_EQ(cv::norm(frame(hands, 0.4), first, cv::NORM_L1), 0.0) << "the same episode";
  EXPECT_GT(cv::norm(later, first, cv::NORM_L1), 1e5) << "another episode, another hand";
  EXPECT_EQ(cv::norm(frame(hands, 1.3), later, cv::NORM_L1), 0.0) << "asked again";
  // Moving sideways at 0.1 m/s for 20 ms, 0.6 m away: about 2 px of smear.
  capture.velocity = vpColVector(6, 0.0);
  capture.velocity[0] = 0.1;
  const cv::Mat slow = frame(plain, 0.0);
  EXPECT_EQ(cv::norm(slow, bare, cv::NORM_L1), 0.0) << "no exposure set: no smear";
  RenderedFrames exposed(setup.target, RenderOptions(),
                         SimulatedCameraScene{{}, {1.0, 1.0}, 1, 0.02});
  const cv::Mat smeared = frame(exposed, 0.0);
  capture.velocity[0] = 0.5;
  const cv::Mat faster = frame(exposed, 0.0);
  const double slow_change = cv::norm(smeared, bare, cv::NORM_L1);
  EXPECT_GT(slow_change, 0.0);
  EXPECT_GT(cv::norm(faster, bare, cv::NORM_L1), 2.0 * slow_change);
  SimulatedCameraScene bad = scene;
  bad.episode_s = {0.0, 1.0};
  EXPECT_THROW(RenderedFrames(setup.target, RenderOptions(), bad), std::invalid_argument);
}

// The simulated camera's frames recorded as the loop asks for them.
class RecordingFrames : public FrameSource {
 public:
  RecordingFrames(const LineTarget& target, const SimulatedCameraScene& scene)
      : frames_(target, RenderOptions(), scene) {}
  bool Grab(const Capture& capture, cv::Mat* gray) override {
    captures.push_back(capture);
    return frames_.Grab(capture, gray);
  }
  std::string Name() const override { return frames_.Name(); }
  bool KnowsTruth() const override { return true; }
  double LatencyS() const override { return frames_.LatencyS(); }
  std::vector<Capture> captures;

 private:
  RenderedFrames frames_;
};

// A frame delivered 60 ms after it was taken (1.5 periods of 40 ms) shows the camera where it
// was then, halfway between the last two frames' poses; the velocity law still converges.
TEST(RunServoLoop, ALateFrameShowsThePoseAtItsCaptureTime) {
  ServoSetup setup = SheetSetup(ServoMode::kVelocity);
  setup.loop.law.gain = 2.0;
  SimulatedCamera robot(StartingAt(kStartcMo, setup.wMo));
  SimulatedCameraScene scene;
  scene.latency_s = 0.06;
  RecordingFrames frames(setup.target, scene);
  std::ostringstream log;
  const ServoRunReport report = RunServoLoop(setup, frames, robot, log);
  ASSERT_EQ(report.status, ServoRunStatus::kConverged) << report.message;
  ASSERT_GT(frames.captures.size(), 10u);
  for (std::size_t k = 3; k < 10; ++k) {
    const Capture& capture = frames.captures[k];
    EXPECT_NEAR(capture.time_s, 0.04 * static_cast<double>(k) - 0.06, 1e-9);
    const vpTranslationVector at = (setup.wMo * capture.true_cMo.inverse()).getTranslationVector();
    const ServoIteration& before = report.iterations[k - 2];
    const ServoIteration& after = report.iterations[k - 1];
    EXPECT_NEAR(at[0] * 1e3, 0.5 * (before.x_mm + after.x_mm), 0.05) << "frame " << k;
    EXPECT_NEAR(at[2] * 1e3, 0.5 * (before.z_mm + after.z_mm), 0.05) << "frame " << k;
  }
  EXPECT_LT(report.iterations.back().true_translation_error_mm, 2.0);
}

// Half a second of latency at a gain of 2/s would make a law acting on its frames' poses
// overshoot and oscillate; the estimate carried to the present by the robot's own motion
// converges as without it, the true error never growing.
TEST(RunServoLoop, TheLawActsOnTheEstimateCarriedToThePresent) {
  ServoSetup setup = SheetSetup(ServoMode::kVelocity);
  setup.loop.law.gain = 2.0;
  SimulatedCamera robot(StartingAt(kStartcMo, setup.wMo));
  SimulatedCameraScene scene;
  scene.latency_s = 0.5;
  RenderedFrames frames(setup.target, RenderOptions(), scene);
  std::ostringstream log;
  const ServoRunReport report = RunServoLoop(setup, frames, robot, log);
  ASSERT_EQ(report.status, ServoRunStatus::kConverged) << report.message;
  for (std::size_t k = 1; k < report.iterations.size(); ++k) {
    EXPECT_LE(report.iterations[k].true_translation_error_mm,
              report.iterations[k - 1].true_translation_error_mm + 1e-3)
        << "frame " << k;
  }
  EXPECT_LT(report.iterations.back().true_translation_error_mm, 2.0);
}

// A position law with a late camera: the first frame after a move was taken while the arm
// was on its way; it is skipped, and the next one, taken with the arm still, is acted on.
TEST(RunServoLoop, AFrameTakenBeforeAMoveEndedIsSkipped) {
  const ServoSetup setup = SheetSetup(ServoMode::kPointAndGo);
  SimulatedCamera robot(StartingAt(kStartcMo, setup.wMo));
  SimulatedCameraScene scene;
  scene.latency_s = 0.06;
  RenderedFrames frames(setup.target, RenderOptions(), scene);
  std::ostringstream log;
  const ServoRunReport report = RunServoLoop(setup, frames, robot, log);
  ASSERT_EQ(report.status, ServoRunStatus::kConverged) << report.message;
  ASSERT_EQ(report.iterations.size(), 4u) << log.str();
  EXPECT_EQ(report.iterations[2].status, "skipped");
  EXPECT_THAT(report.iterations[2].held, HasSubstr("taken before the move ended"));
  EXPECT_EQ(report.moves, 1);
  EXPECT_LT(report.iterations.back().true_translation_error_mm, 1.0);
}

// A camera that says when it took its frames (as V4L2 timestamps do): the loop takes each
// frame as seen from where the robot was then. This one's frames all claim to be ten seconds
// old: the first ones, the robot still, are taken as they are; after the first move every
// frame is older than the move, skipped, and the run stops on it rather than waiting for ever.
class StaleFrames : public FrameSource {
 public:
  explicit StaleFrames(const LineTarget& target) : frames_(target, RenderOptions()) {}
  bool Grab(const Capture& capture, cv::Mat* gray) override { return frames_.Grab(capture, gray); }
  std::string Name() const override { return "a camera ten seconds late"; }
  std::optional<double> TakenAt() const override {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
               .count() -
           10.0;
  }

 private:
  RenderedFrames frames_;
};

TEST(RunServoLoop, AFramesTimestampSaysWhereTheCameraWasWhenItWasTaken) {
  ServoSetup setup = SheetSetup(ServoMode::kExponential);
  setup.loop.max_lost_frames = 5;
  SimulatedCamera robot(StartingAt(kStartcMo, setup.wMo));
  StaleFrames frames(setup.target);
  std::ostringstream log;
  const ServoRunReport report = RunServoLoop(setup, frames, robot, log);
  EXPECT_EQ(report.status, ServoRunStatus::kError) << report.message;
  EXPECT_THAT(report.message, HasSubstr("6 frames in a row were taken"));
  EXPECT_THAT(report.message, HasSubstr("before the last move ended"));
  EXPECT_EQ(report.moves, 1);
  ASSERT_EQ(report.iterations.size(), 8u) << log.str();  // frames 2-7 skipped
  EXPECT_EQ(report.iterations[2].status, "skipped");
}

TEST(RecordedFrames, ASourcesTimestampIsHandedOnWithItsFrame) {
  class Stamped : public ImageSource {
   public:
    bool Next(Frame* frame) override {
      frame->gray = cv::Mat(4, 4, CV_8UC1, cv::Scalar(1));
      frame->taken_s = 12.5 + static_cast<double>(count_++);
      return true;
    }
    std::string Name() const override { return "stamped"; }

   private:
    int count_ = 0;
  };
  RecordedFrames frames(std::make_unique<Stamped>());
  EXPECT_FALSE(frames.TakenAt().has_value());
  cv::Mat gray;
  ASSERT_TRUE(frames.Grab(Capture{}, &gray));
  EXPECT_EQ(frames.TakenAt(), 12.5);
  EXPECT_FALSE(frames.AtEnd());  // reads the next ahead: the frame handed out keeps its time
  EXPECT_EQ(frames.TakenAt(), 12.5);
  ASSERT_TRUE(frames.Grab(Capture{}, &gray));
  EXPECT_EQ(frames.TakenAt(), 13.5);
}

// A step longer than max_step_m is refused before the robot moves: the run stops (limit) and
// names the limit in the caller's words when it gave them, else as the setup's field.
TEST(RunServoLoop, AStepBeyondTheLimitStopsTheRunBeforeTheRobotMoves) {
  for (const bool named : {false, true}) {
    ServoSetup setup = SheetSetup(ServoMode::kPointAndGo);
    setup.loop.max_step_m = 0.01;
    if (named) setup.names = {{"loop.max_step_m", "servo.max_step_m"}};
    const SimulatedCameraOptions start = StartingAt(kStartcMo, setup.wMo);
    SimulatedCamera robot(start);
    RenderedFrames frames(setup.target, RenderOptions());
    std::ostringstream log;
    const ServoRunReport report = RunServoLoop(setup, frames, robot, log);
    EXPECT_EQ(report.status, ServoRunStatus::kLimit) << report.message;
    EXPECT_THAT(report.message, HasSubstr(std::string(named ? "exceeds servo.max_step_m = 0.01"
                                                            : "exceeds loop.max_step_m = 0.01")));
    EXPECT_THAT(report.message, HasSubstr("the robot did not move"));
    EXPECT_EQ(report.moves, 0);
    EXPECT_TRUE(report.robot_stopped);
    const vpHomogeneousMatrix end = robot.GetPosition(RobotFrame::kCamera).pose;
    EXPECT_LT((end.getTranslationVector() - start.wMc.getTranslationVector()).frobeniusNorm(),
              1e-12);
  }
}

// The iteration limit ends a run that has not converged, and says which limit it was.
TEST(RunServoLoop, TheIterationLimitEndsTheRunAndSaysSo) {
  ServoSetup setup = SheetSetup(ServoMode::kExponential);
  setup.loop.max_iterations = 2;
  SimulatedCamera robot(StartingAt(kStartcMo, setup.wMo));
  RenderedFrames frames(setup.target, RenderOptions());
  std::ostringstream log;
  const ServoRunReport report = RunServoLoop(setup, frames, robot, log);
  EXPECT_EQ(report.status, ServoRunStatus::kIterationLimit) << report.message;
  EXPECT_THAT(report.message, HasSubstr("loop.max_iterations = 2"));
  EXPECT_TRUE(report.robot_stopped);
}

// A frame rolled by 15 degrees, the robot still: the pose disagrees with the motion, so the
// loop holds rather than act on it, then finds the target where it was and carries on.
TEST(RunServoLoop, APoseJumpIsHeldPastNotActedOn) {
  ServoSetup setup = SheetSetup(ServoMode::kVelocity);
  setup.loop.law.gain = 2.0;
  SimulatedCamera robot(StartingAt(kStartcMo, setup.wMo));
  RenderedFrames frames(setup.target, RenderOptions());
  constexpr int kRolled = 4;
  ServoLoopHooks hooks;
  hooks.on_grab = [](int iteration, cv::Mat* gray) {
    if (iteration != kRolled) return;
    const cv::Point2f centre(0.5f * (gray->cols - 1), 0.5f * (gray->rows - 1));
    cv::Mat rolled;
    cv::warpAffine(*gray, rolled, cv::getRotationMatrix2D(centre, 15.0, 1.0), gray->size(),
                   cv::INTER_LINEAR, cv::BORDER_REPLICATE);
    *gray = rolled;
  };
  std::vector<int> moved_at;
  hooks.on_move = [&](int iteration) { moved_at.push_back(iteration); };
  std::ostringstream log;
  const ServoRunReport report = RunServoLoop(setup, frames, robot, log, hooks);
  ASSERT_EQ(report.status, ServoRunStatus::kConverged) << report.message;
  const ServoIteration& rolled = report.iterations.at(kRolled);
  EXPECT_EQ(rolled.status, "held");
  EXPECT_THAT(rolled.held, HasSubstr("pose jump"));
  EXPECT_EQ(std::count(moved_at.begin(), moved_at.end(), kRolled), 0);
  EXPECT_GE(report.holds, 1);
  EXPECT_LT(report.iterations.back().true_translation_error_mm, 2.0);
}

// Frames of another size than the camera's stop the run before anything moves, and the
// message names the setup's size in the caller's words.
TEST(RunServoLoop, AFrameOfAnotherSizeStopsTheRun) {
  ServoSetup setup = SheetSetup(ServoMode::kPointAndGo);
  setup.names = {{"width", "camera.width"}, {"height", "camera.height"}};
  SimulatedCamera robot(StartingAt(kStartcMo, setup.wMo));
  RenderedFrames frames(setup.target, RenderOptions());
  ServoLoopHooks hooks;
  hooks.on_grab = [](int, cv::Mat* gray) { cv::resize(cv::Mat(*gray), *gray, cv::Size(320, 240)); };
  std::ostringstream log;
  const ServoRunReport report = RunServoLoop(setup, frames, robot, log, hooks);
  EXPECT_EQ(report.status, ServoRunStatus::kError) << report.message;
  EXPECT_THAT(report.message,
              HasSubstr("320x240 frames but camera.width x camera.height is 640x480"));
  EXPECT_EQ(report.moves, 0);
}

// A hand over the view for three frames in the middle of a velocity run: the loop holds (a
// zero twist each frame: the camera stays where it was), finds the target again, confirms it
// with the camera still, and carries on to the goal. The CSV says where it held and why.
TEST(RunServoLoop, AVelocityRunHoldsStillUnderAHandAndCarriesOn) {
  ServoSetup setup = SheetSetup(ServoMode::kVelocity);
  setup.loop.law.gain = 2.0;
  SimulatedCamera robot(StartingAt(kStartcMo, setup.wMo));
  RenderedFrames frames(setup.target, RenderOptions());
  ServoLoopHooks hooks;
  constexpr int kFirstHidden = 5, kHidden = 3;
  hooks.on_grab = [](int iteration, cv::Mat* gray) {
    if (iteration >= kFirstHidden && iteration < kFirstHidden + kHidden) gray->setTo(40);
  };
  std::vector<int> moved_at;
  hooks.on_move = [&](int iteration) { moved_at.push_back(iteration); };
  std::ostringstream log;
  const ServoRunReport report = RunServoLoop(setup, frames, robot, log, hooks);
  ASSERT_EQ(report.status, ServoRunStatus::kConverged) << report.message;
  // Held: the three hidden frames and the one found again; the next confirms and moves.
  for (int i = kFirstHidden; i <= kFirstHidden + kHidden; ++i) {
    const ServoIteration& row = report.iterations[static_cast<std::size_t>(i)];
    EXPECT_EQ(row.status, "held") << "frame " << i;
    EXPECT_EQ(row.x_mm, report.iterations[kFirstHidden].x_mm) << "frame " << i;
    EXPECT_EQ(row.z_mm, report.iterations[kFirstHidden].z_mm) << "frame " << i;
    EXPECT_EQ(std::count(moved_at.begin(), moved_at.end(), i), 0) << "frame " << i;
  }
  EXPECT_THAT(report.iterations[kFirstHidden].held, HasSubstr("no pose: "));
  EXPECT_EQ(std::count(moved_at.begin(), moved_at.end(), kFirstHidden + kHidden + 1), 1);
  EXPECT_EQ(report.holds, 1);
  EXPECT_EQ(report.held_frames, kHidden + 1);
  EXPECT_LT(report.iterations.back().true_translation_error_mm, 2.0);
  std::ostringstream csv;
  WriteServoCsv(report, csv);
  EXPECT_THAT(csv.str(), HasSubstr(",true_rotation_error_deg,held,status\n"));
  EXPECT_THAT(csv.str(), HasSubstr(",\"no pose: "));
  EXPECT_THAT(csv.str(), HasSubstr(",\"found again: the next frame"));
}

}  // namespace
}  // namespace oal
