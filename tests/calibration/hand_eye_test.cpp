// The hand-eye transform (calibration/hand_eye.h) from pose pairs made through a known
// mounting, with and without noise; sets of pairs that cannot determine it refused with the
// reason; the routine (calibration/hand_eye_routine.h) on the simulated arm through the safety
// runner: stations taken, stations outside the box skipped before anything moves, an
// interrupt stopping the arm.
#include "calibration/hand_eye.h"

#include <gtest/gtest.h>
#include <visp3/core/vpMath.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "calibration/hand_eye_routine.h"
#include "robots/safe_robot.h"
#include "robots/simulated_camera.h"

namespace oal {
namespace {

// A camera 6 cm beside the flange and 4 cm ahead, turned a quarter about the tool axis and
// tilted 3 degrees: what a bracket gives.
vpHomogeneousMatrix TrueMounting() {
  return vpHomogeneousMatrix(0.0, 0.06, 0.04, vpMath::rad(3.0), 0.0, vpMath::rad(90.0));
}

// The end effector looking down at the target 0.5 m below.
vpHomogeneousMatrix StartWMe() {
  return vpHomogeneousMatrix(0.5, 0.0, 0.6, vpMath::rad(180.0), 0.0, 0.0);
}

struct Scene {
  vpHomogeneousMatrix eMc = TrueMounting();
  vpHomogeneousMatrix wMo;
  Scene() {
    const vpHomogeneousMatrix cMo(0.01, -0.02, 0.5, 0.0, 0.0, vpMath::rad(20.0));
    wMo = StartWMe() * eMc * cMo;
  }
  vpHomogeneousMatrix CMo(const vpHomogeneousMatrix& wMe) const {
    return (wMe * eMc).inverse() * wMo;
  }
};

// A pose estimate's noise: the depth worst, as for a pose from a target's image.
vpHomogeneousMatrix Noisy(const vpHomogeneousMatrix& cMo, std::mt19937* random) {
  std::normal_distribution<double> lateral(0.0, 0.0002), depth(0.0, 0.0006),
      angle(0.0, vpMath::rad(0.03));
  const vpHomogeneousMatrix noise(lateral(*random), lateral(*random), depth(*random),
                                  angle(*random), angle(*random), angle(*random));
  return noise * cMo;
}

std::vector<HandEyePair> PairsAt(const std::vector<vpHomogeneousMatrix>& stations,
                                 const Scene& scene, std::mt19937* random = nullptr) {
  std::vector<HandEyePair> pairs;
  for (const vpHomogeneousMatrix& wMe : stations) {
    const vpHomogeneousMatrix cMo = scene.CMo(wMe);
    pairs.push_back({wMe, random ? Noisy(cMo, random) : cMo});
  }
  return pairs;
}

std::vector<vpHomogeneousMatrix> Stations(const Scene& scene, int count,
                                          const vpHomogeneousMatrix& guess) {
  HandEyeStationOptions options;
  options.count = count;
  return HandEyeStations(StartWMe(), guess, scene.CMo(StartWMe()), options);
}

void ExpectNear(const vpHomogeneousMatrix& expected, const vpHomogeneousMatrix& actual,
                double max_mm, double max_deg) {
  const PoseDistance d = Distance(expected, actual);
  EXPECT_LE(d.translation_m * 1e3, max_mm);
  EXPECT_LE(vpMath::deg(d.rotation_rad), max_deg);
}

TEST(HandEye, RecoversTheMountingFromExactPairs) {
  const Scene scene;
  const HandEyeResult result = CalibrateHandEye(PairsAt(Stations(scene, 6, scene.eMc), scene));
  ExpectNear(scene.eMc, result.eMc, 1e-3, 1e-4);
  ExpectNear(scene.wMo, result.wMo, 1e-3, 1e-4);
  EXPECT_LT(result.rms_translation_mm, 1e-3);
  EXPECT_GT(result.axis_spread_deg, 45.0);
  EXPECT_TRUE(result.advice.empty());
}

TEST(HandEye, RecoversTheMountingWithinAMillimetreFromTwelveNoisyPairs) {
  const Scene scene;
  for (const unsigned seed : {1u, 2u, 3u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::mt19937 random(seed);
    const HandEyeResult result =
        CalibrateHandEye(PairsAt(Stations(scene, 12, scene.eMc), scene, &random));
    ExpectNear(scene.eMc, result.eMc, 1.0, 0.2);
    EXPECT_GT(result.rms_translation_mm, 0.0);
    EXPECT_EQ(result.residuals.size(), 12u);
  }
}

TEST(HandEye, StationsKeepTheTargetWhereItIsSeenWhenTheGuessIsRight) {
  const Scene scene;
  const vpHomogeneousMatrix start_cMo = scene.CMo(StartWMe());
  for (const vpHomogeneousMatrix& wMe : Stations(scene, 12, scene.eMc)) {
    const vpTranslationVector at = scene.CMo(wMe).getTranslationVector();
    for (unsigned int i = 0; i < 3; ++i) EXPECT_NEAR(at[i], start_cMo[i][3], 1e-9);
    EXPECT_GT(Distance(StartWMe(), wMe).rotation_rad, vpMath::rad(5.0));
  }
}

TEST(HandEye, AGuessOffByCentimetresStillKeepsTheTargetInViewAndGivesTheSameResult) {
  const Scene scene;
  // The user's guess: the bracket's offset unknown (zero), the quarter turn right.
  const vpHomogeneousMatrix guess(0, 0, 0, 0, 0, vpMath::rad(90.0));
  const std::vector<vpHomogeneousMatrix> stations = Stations(scene, 12, guess);
  for (const vpHomogeneousMatrix& wMe : stations) {
    const vpTranslationVector at = scene.CMo(wMe).getTranslationVector();
    // Within a 640 x 480, px 600 camera's view, with room for the target around its centre.
    EXPECT_LT(std::fabs(at[0] / at[2]) * 600.0, 200.0);
    EXPECT_LT(std::fabs(at[1] / at[2]) * 600.0, 150.0);
  }
  const HandEyeResult result = CalibrateHandEye(PairsAt(stations, scene));
  ExpectNear(scene.eMc, result.eMc, 1e-3, 1e-4);
}

TEST(HandEye, RefusesTooFewPairs) {
  const Scene scene;
  try {
    CalibrateHandEye(PairsAt(Stations(scene, 4, scene.eMc), scene), HandEyeOptions{6, 5.0});
    FAIL() << "four pairs accepted where six are needed";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("4 pairs"), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("at least 6"), std::string::npos) << error.what();
  }
}

TEST(HandEye, RefusesTurnsAboutOneAxisOnly) {
  const Scene scene;
  std::vector<vpHomogeneousMatrix> stations;
  for (int k = 0; k < 6; ++k) {
    stations.push_back(StartWMe() *
                       vpHomogeneousMatrix(0.01 * k, 0, 0, 0, 0, vpMath::rad(10.0 * k)));
  }
  try {
    CalibrateHandEye(PairsAt(stations, scene));
    FAIL() << "turns about one axis accepted";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("one axis"), std::string::npos) << error.what();
  }
}

TEST(HandEye, RefusesAnArmThatBarelyTurned) {
  const Scene scene;
  std::vector<vpHomogeneousMatrix> stations;
  for (int k = 0; k < 6; ++k) {
    stations.push_back(StartWMe() * vpHomogeneousMatrix(0.02 * k, 0.01 * (k % 2), 0,
                                                        vpMath::rad(0.5 * (k % 2)), 0, 0));
  }
  try {
    CalibrateHandEye(PairsAt(stations, scene));
    FAIL() << "stations without turns accepted";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("turn it by at least"), std::string::npos)
        << error.what();
  }
}

TEST(HandEye, RefusesTwoPairsFromOneStation) {
  const Scene scene;
  std::vector<HandEyePair> pairs = PairsAt(Stations(scene, 6, scene.eMc), scene);
  pairs.push_back(pairs[2]);
  try {
    CalibrateHandEye(pairs);
    FAIL() << "a repeated station accepted";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("pairs 3 and 7"), std::string::npos) << error.what();
  }
}

TEST(HandEye, SaysWhenThePairsDisagree) {
  const Scene scene;
  std::vector<HandEyePair> pairs = PairsAt(Stations(scene, 8, scene.eMc), scene);
  pairs[3].cMo = vpHomogeneousMatrix(0.02, 0, 0, 0, 0, 0) * pairs[3].cMo;  // the target bumped
  const HandEyeResult result = CalibrateHandEye(pairs);
  ASSERT_FALSE(result.advice.empty());
  EXPECT_NE(result.advice.back().find("did not move"), std::string::npos);
  // The bumped pair stands out.
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    if (i == 3) continue;
    EXPECT_LT(result.residuals[i].translation_mm, result.residuals[3].translation_mm);
  }
}

TEST(HandEye, OptionsOutOfRangeAreRefusedByName) {
  HandEyeOptions options;
  options.min_pairs = 2;
  EXPECT_THROW(options.Check(), std::invalid_argument);
  HandEyeStationOptions stations;
  stations.tilt_deg = 60.0;
  try {
    stations.Check();
    FAIL();
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("tilt_deg"), std::string::npos);
  }
}

// The routine on the simulated arm, its camera mounted by TrueMounting(); the "camera" gives
// the true pose of the target.
struct Rig {
  Scene scene;
  SimulatedCamera arm;
  SafeRobot robot;
  int frames = 0;

  explicit Rig(const SafetyOptions& safety) : arm(ArmOptions(scene)), robot(arm, safety) {
    EXPECT_TRUE(robot.Connect().ok());
    EXPECT_TRUE(robot.Enable().ok());
  }
  static SimulatedCameraOptions ArmOptions(const Scene& scene) {
    SimulatedCameraOptions options;
    options.eMc = scene.eMc;
    options.wMc = StartWMe() * scene.eMc;
    return options;
  }
  MeasureTarget Camera() {
    return [this](std::string*) -> std::optional<vpHomogeneousMatrix> {
      ++frames;
      return arm.wMc().inverse() * scene.wMo;
    };
  }
};

SafetyOptions BoxAround(double half_width_m) {
  SafetyOptions safety;
  safety.workspace_frame = RobotFrame::kEndEffector;
  const vpTranslationVector at = StartWMe().getTranslationVector();
  for (unsigned int i = 0; i < 3; ++i) {
    safety.workspace_min_m[i] = at[i] - half_width_m;
    safety.workspace_max_m[i] = at[i] + half_width_m;
  }
  return safety;
}

TEST(HandEyeRoutine, TakesAPairAtEveryStationAndReturnsTheArmToItsStart) {
  Rig rig(BoxAround(0.5));
  std::vector<std::string> lines;
  const HandEyeRoutineResult result =
      RunHandEyeRoutine(rig.robot, TrueMounting(), rig.Camera(), HandEyeRoutineOptions(),
                        [&](const std::string& line) { lines.push_back(line); });
  ASSERT_TRUE(result.completed) << result.stopped;
  EXPECT_EQ(result.pairs.size(), 12u);
  EXPECT_EQ(lines.size(), 12u);
  EXPECT_NE(lines.front().find("station 1/12: pair 1 taken"), std::string::npos) << lines.front();
  ExpectNear(StartWMe(), rig.robot.GetPosition(RobotFrame::kEndEffector).pose, 1e-3, 1e-4);
  ExpectNear(TrueMounting(), CalibrateHandEye(result.pairs).eMc, 1e-3, 1e-4);
}

TEST(HandEyeRoutine, SkipsStationsOutsideTheWorkspaceBoxBeforeMovingThere) {
  // A box 10 cm wide: the stations pivot about the target 0.5 m away, the full tilts (15 deg)
  // swing the flange about 13 cm, the part ones (9 deg) about 8 cm; half of a part tilt fits,
  // half of a full one not.
  Rig rig(BoxAround(0.05));
  double farthest_m = 0.0;
  const vpTranslationVector start = StartWMe().getTranslationVector();
  MeasureTarget camera = [&](std::string*) {
    const vpTranslationVector at = (rig.arm.wMc() * rig.scene.eMc.inverse()).getTranslationVector();
    for (unsigned int i = 0; i < 3; ++i) {
      farthest_m = std::max(farthest_m, std::fabs(at[i] - start[i]));
    }
    return std::optional<vpHomogeneousMatrix>(rig.arm.wMc().inverse() * rig.scene.wMo);
  };
  std::vector<std::string> lines;
  const HandEyeRoutineResult result =
      RunHandEyeRoutine(rig.robot, TrueMounting(), camera, HandEyeRoutineOptions(),
                        [&](const std::string& line) { lines.push_back(line); });
  ASSERT_TRUE(result.completed) << result.stopped;
  int skipped = 0, halved = 0;
  for (const HandEyeStation& station : result.stations) {
    if (station.taken) continue;
    ++skipped;
    EXPECT_NE(station.skipped.find("skipped before moving"), std::string::npos) << station.skipped;
    EXPECT_NE(station.skipped.find("workspace"), std::string::npos) << station.skipped;
  }
  for (const std::string& line : lines)
    halved += line.find("at half the turn") != std::string::npos;
  EXPECT_GT(skipped, 0);
  EXPECT_GT(halved, 0);
  EXPECT_EQ(result.pairs.size() + skipped, 12u);
  EXPECT_LE(farthest_m, 0.05 + 1e-9);
  EXPECT_EQ(rig.robot.state(), SafeRobotState::kEnabled);  // skipping latches nothing
}

TEST(HandEyeRoutine, AStationWhereTheTargetWouldLeaveTheViewIsNotVisited) {
  Rig rig(BoxAround(0.5));
  int judged = 0;
  const TargetInView in_view = [&](const vpHomogeneousMatrix&) {
    ++judged;
    return std::string("off to the side");
  };
  const HandEyeRoutineResult result = RunHandEyeRoutine(rig.robot, TrueMounting(), rig.Camera(),
                                                        HandEyeRoutineOptions(), nullptr, in_view);
  EXPECT_EQ(judged, 12 * 4);  // each station, then its three alternatives
  EXPECT_TRUE(result.pairs.empty());
  ASSERT_EQ(result.stations.size(), 12u);
  EXPECT_NE(result.stations[0].skipped.find("off to the side"), std::string::npos);
  EXPECT_EQ(rig.frames, 4);  // the start's frames only: the arm never left
}

TEST(HandEyeRoutine, AnInterruptStopsTheArmAndEndsTheRoutine) {
  Rig rig(BoxAround(0.5));
  std::atomic<bool> interrupt{false};
  MeasureTarget camera = [&](std::string*) {
    if (++rig.frames == 11) interrupt = true;  // at the second station
    return std::optional<vpHomogeneousMatrix>(rig.arm.wMc().inverse() * rig.scene.wMo);
  };
  const HandEyeRoutineResult result = RunHandEyeRoutine(
      rig.robot, TrueMounting(), camera, HandEyeRoutineOptions(), nullptr, nullptr, &interrupt);
  EXPECT_FALSE(result.completed);
  EXPECT_NE(result.stopped.find("interrupted"), std::string::npos) << result.stopped;
  EXPECT_EQ(rig.robot.state(), SafeRobotState::kStopped);
  EXPECT_LT(result.pairs.size(), 4u);
}

TEST(HandEyeRoutine, NoTargetAtTheStartMovesNothing) {
  Rig rig(BoxAround(0.5));
  MeasureTarget blind = [](std::string* why) {
    *why = "the target is not in view";
    return std::optional<vpHomogeneousMatrix>();
  };
  const HandEyeRoutineResult result =
      RunHandEyeRoutine(rig.robot, TrueMounting(), blind, HandEyeRoutineOptions(), nullptr);
  EXPECT_FALSE(result.completed);
  EXPECT_NE(result.stopped.find("not in view"), std::string::npos) << result.stopped;
  ExpectNear(StartWMe(), rig.robot.GetPosition(RobotFrame::kEndEffector).pose, 1e-6, 1e-6);
}

TEST(HandEyeRoutine, AStationWithoutATargetIsSkippedWithTheReason) {
  Rig rig(BoxAround(0.5));
  MeasureTarget camera = [&](std::string* why) -> std::optional<vpHomogeneousMatrix> {
    // Blind while the arm is at the fourth station (4 frames at the start and at each station,
    // 12 at most).
    ++rig.frames;
    if (rig.frames > 16 && rig.frames <= 16 + 12) {
      *why = "the target is not in view";
      return std::nullopt;
    }
    return rig.arm.wMc().inverse() * rig.scene.wMo;
  };
  const HandEyeRoutineResult result =
      RunHandEyeRoutine(rig.robot, TrueMounting(), camera, HandEyeRoutineOptions(), nullptr);
  ASSERT_TRUE(result.completed) << result.stopped;
  ASSERT_EQ(result.stations.size(), 12u);
  EXPECT_FALSE(result.stations[3].taken);
  EXPECT_NE(result.stations[3].skipped.find("not in view"), std::string::npos);
  EXPECT_EQ(result.pairs.size(), 11u);
}

}  // namespace
}  // namespace oal
