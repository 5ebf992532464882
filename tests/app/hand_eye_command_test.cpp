// `oalservo hand-eye` as a user runs it: the simulated arm with a camera on a bracket moved
// through the stations, the mounting written as a configuration that servo reads back; pairs
// recorded and solved again; bad input a clear error with nothing written.
#include "app/hand_eye_command.h"

#include <gtest/gtest.h>
#include <visp3/core/vpMath.h>

#include <sstream>
#include <string>

#include "app/config.h"
#include "app/servo_command.h"
#include "loop/lens_estimate.h"  // kLensFrames
#include "robots/robot.h"
#include "tests/app/command_test_util.h"
#include "tests/test_util.h"

namespace oal {
namespace {

using test::OalservoRun;
using test::ReadText;
using test::RunOalservo;
using test::TestDir;
using test::WriteText;

const vpHomogeneousMatrix kBracket(0.02, -0.04, 0.03, vpMath::rad(2.0), vpMath::rad(-1.0),
                                   vpMath::rad(90.0));

// The built-in simulated camera, mounted on its flange by kBracket: believed (eMc) and true.
std::string BracketConfig(const TestDir& dir) {
  const std::string path = dir / "bracket.yaml";
  WriteText(path,
            "camera:\n  eMc: " + PoseYaml(kBracket) + "\n  true_eMc: " + PoseYaml(kBracket) + "\n");
  return path;
}

TEST(HandEyeCommand, MeasuresTheMountingOfTheSimulatedArmAndServoReadsIt) {
  const TestDir dir;
  const std::string config = BracketConfig(dir);
  const std::string out = dir / "out/hand-eye.yaml";
  const OalservoRun run = RunOalservo(dir, "hand-eye --config '" + config + "' --record '" +
                                               (dir / "out/pairs.csv") + "' --out '" + out + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err << run.out;
  EXPECT_NE(run.out.find("station 12/12: pair 12 taken"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("the configuration's eMc differs by"), std::string::npos) << run.out;

  // The file is a configuration: applied after the robot's, it sets camera.eMc.
  const AppConfig read = LoadConfig(out, LoadConfig(config, DefaultServoConfig()));
  const PoseDistance error = Distance(kBracket, read.camera.eMc);
  EXPECT_LT(error.translation_m, 1e-3);
  EXPECT_LT(vpMath::deg(error.rotation_rad), 0.2);

  // The pairs it recorded give the same mounting again.
  const std::vector<HandEyePair> pairs = ReadHandEyePairs(dir / "out/pairs.csv");
  EXPECT_EQ(pairs.size(), 12u);
  const OalservoRun again = RunOalservo(dir, "hand-eye --pairs '" + (dir / "out/pairs.csv") +
                                                 "' --out '" + (dir / "again.yaml") + "'");
  ASSERT_EQ(again.exit_code, 0) << again.err;
  const AppConfig reread = LoadConfig(dir / "again.yaml", DefaultServoConfig());
  EXPECT_LT(Distance(read.camera.eMc, reread.camera.eMc).translation_m, 1e-6);
}

// A camera nobody calibrated (camera.estimate_distortion): the lens is told from the stripes
// before the arm moves, as the servo loop does, and the mounting still comes out.
TEST(HandEyeCommand, TellsTheLensFirstWhenTheConfigAsksIt) {
  const TestDir dir;
  const std::string config = dir / "lens.yaml";
  WriteText(config, "camera:\n  kdu: 0.15\n  estimate_distortion: true\n  eMc: " +
                        PoseYaml(kBracket) + "\n  true_eMc: " + PoseYaml(kBracket) + "\n");
  const OalservoRun run =
      RunOalservo(dir, "hand-eye --config '" + config + "' --out '" + (dir / "he.yaml") + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err << run.out;
  EXPECT_NE(
      run.out.find("lens told from the stripes of " + std::to_string(kLensFrames) + " frames"),
      std::string::npos)
      << run.out;
  const AppConfig read = LoadConfig(dir / "he.yaml", LoadConfig(config, DefaultServoConfig()));
  const PoseDistance error = Distance(kBracket, read.camera.eMc);
  EXPECT_LT(error.translation_m, 1e-3);
  EXPECT_LT(vpMath::deg(error.rotation_rad), 0.2);
}

TEST(HandEyeCommand, PairsRoundTripThroughTheCsv) {
  const std::vector<HandEyePair> pairs = {{vpHomogeneousMatrix(0.5, 0.1, 0.6, 3.0, 0.2, -0.1),
                                           vpHomogeneousMatrix(0, 0.01, 0.5, 0, 0, 1)},
                                          {vpHomogeneousMatrix(-0.2, 0.3, 0.4, 0.1, -2.5, 0.3),
                                           vpHomogeneousMatrix(0.1, 0, 0.7, 0.2, 0, 0)}};
  const TestDir dir;
  std::ostringstream csv;
  WriteHandEyePairs(pairs, csv);
  WriteText(dir / "pairs.csv", csv.str());
  const std::vector<HandEyePair> read = ReadHandEyePairs(dir / "pairs.csv");
  ASSERT_EQ(read.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_LT(Distance(pairs[i].wMe, read[i].wMe).translation_m, 1e-8);
    EXPECT_LT(Distance(pairs[i].wMe, read[i].wMe).rotation_rad, 1e-8);
    EXPECT_LT(Distance(pairs[i].cMo, read[i].cMo).rotation_rad, 1e-8);
  }
}

TEST(HandEyeCommand, AMalformedPairsFileNamesTheLineAndTheColumn) {
  const TestDir dir;
  std::ostringstream csv;
  WriteHandEyePairs({{vpHomogeneousMatrix(), vpHomogeneousMatrix(0, 0, 0.5, 0, 0, 0)}}, csv);
  std::string text = csv.str();
  text += "0.1,0.2,0.3,0,0,0,0,0,0.5,0,zero,0\n";
  WriteText(dir / "pairs.csv", text);
  const OalservoRun run = RunOalservo(
      dir, "hand-eye --pairs '" + (dir / "pairs.csv") + "' --out '" + (dir / "he.yaml") + "'");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("pairs.csv:3: cMo_ry_deg = 'zero' is not a number"), std::string::npos)
      << run.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "he.yaml"));

  WriteText(dir / "header.csv", "x,y,z\n");
  const OalservoRun header = RunOalservo(
      dir, "hand-eye --pairs '" + (dir / "header.csv") + "' --out '" + (dir / "he.yaml") + "'");
  EXPECT_EQ(header.exit_code, 1);
  EXPECT_NE(header.err.find("header.csv:1: the header must be"), std::string::npos) << header.err;
}

TEST(HandEyeCommand, TooFewPairsIsAClearErrorAndWritesNothing) {
  const TestDir dir;
  std::ostringstream csv;
  WriteHandEyePairs(
      {{vpHomogeneousMatrix(), vpHomogeneousMatrix(0, 0, 0.5, 0, 0, 0)},
       {vpHomogeneousMatrix(0.1, 0, 0, 0, 0.3, 0), vpHomogeneousMatrix(0, 0, 0.5, 0, 0, 0)}},
      csv);
  WriteText(dir / "pairs.csv", csv.str());
  const OalservoRun run = RunOalservo(
      dir, "hand-eye --pairs '" + (dir / "pairs.csv") + "' --out '" + (dir / "he.yaml") + "'");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("2 pairs: the hand-eye transform needs at least 4"), std::string::npos)
      << run.err;
  EXPECT_NE(run.err.find("nothing written to"), std::string::npos) << run.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "he.yaml"));
}

TEST(HandEyeCommand, ABadCommandLineSaysWhatToGive) {
  const TestDir dir;
  const OalservoRun neither = RunOalservo(dir, "hand-eye --out '" + (dir / "he.yaml") + "'");
  EXPECT_EQ(neither.exit_code, 2);
  EXPECT_NE(neither.err.find("give either --config"), std::string::npos) << neither.err;
  const OalservoRun tilt = RunOalservo(dir, "hand-eye --config '" + BracketConfig(dir) +
                                                "' --tilt 80 --out '" + (dir / "he.yaml") + "'");
  EXPECT_EQ(tilt.exit_code, 1);
  EXPECT_NE(tilt.err.find("--tilt"), std::string::npos) << tilt.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "he.yaml"));
}

TEST(HandEyeCommand, AReplayHasNoArmToMove) {
  const TestDir dir;
  WriteText(dir / "replay.yaml", "source: {type: replay, path: frames/%04d.png}\n");
  const OalservoRun run = RunOalservo(
      dir, "hand-eye --config '" + (dir / "replay.yaml") + "' --out '" + (dir / "he.yaml") + "'");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("replay.yaml:1: source.type is replay"), std::string::npos) << run.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "he.yaml"));
}

}  // namespace
}  // namespace oal
