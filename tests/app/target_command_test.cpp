#include "app/target_command.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/config.h"
#include "app/render_command.h"
#include "print/target_svg.h"
#include "scene/scene.h"
#include "tests/print/svg_reading.h"
#include "tests/test_util.h"

namespace oal {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;
using namespace test;  // the SVG reading helpers

TEST(TargetCommand, WithoutATargetThePagesSheetTarget) {
  TargetCommandOptions options;
  EXPECT_EQ(options.page, "a3");
  EXPECT_FALSE(options.landscape);
  EXPECT_EQ(TargetToPrint(options).name, "four-line-a3");
  options.page = "a4";
  EXPECT_EQ(TargetToPrint(options).name, "four-line-a4");
  options.page = "letter";
  EXPECT_EQ(TargetToPrint(options).name, "four-line-letter");
  options.page = "full";
  EXPECT_EQ(TargetToPrint(options).name, "four-line-a3");
  options.target = "four-line-board";
  EXPECT_EQ(TargetToPrint(options).name, "four-line-board");
  options.target = "four-line";  // the older name
  EXPECT_EQ(TargetToPrint(options).name, "four-line-board");
}

TEST(TargetCommand, OptionErrorsNameTheOption) {
  const auto error = [](auto change) {
    TargetCommandOptions options;
    options.out = "t.svg";
    change(&options);
    try {
      options.Check();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(error([](TargetCommandOptions*) {}), "no error");
  const std::string bad_target = error([](TargetCommandOptions* o) { o->target = "six-line"; });
  EXPECT_THAT(bad_target, HasSubstr("--target = six-line: it is one of four-line-a3"));
  EXPECT_THAT(bad_target, HasSubstr("four-line-board"));
  EXPECT_THAT(error([](TargetCommandOptions* o) {
                o->target = "four-line-a4";
                o->config = "x.yaml";
              }),
              HasSubstr("--target four-line-a4 and --config x.yaml both name a target"));
  EXPECT_THAT(error([](TargetCommandOptions* o) { o->page = "a5"; }), HasSubstr("--page = a5"));
  EXPECT_THAT(error([](TargetCommandOptions* o) {
                o->page = "full";
                o->landscape = true;
              }),
              HasSubstr("--landscape is for a sheet"));
  EXPECT_THAT(error([](TargetCommandOptions* o) { o->out.clear(); }), HasSubstr("--out"));
}

TEST(TargetCommand, WritesTheConfigsTargetAtomically) {
  test::TestDir dir;
  test::WriteText(dir / "small.yaml",
                  "target:\n  name: small\n  board_width_m: 0.15\n  board_height_m: 0.2\n"
                  "  lines:\n"
                  "    - {from: [-0.05, -0.1], to: [-0.05, 0.1], width: 0.012}\n"
                  "    - {from: [-0.075, 0.031], to: [0.075, -0.0423], width: 0.00733}\n"
                  "    - {from: [0, -0.1], to: [0.07, 0.1], width: 0.005}\n");
  TargetCommandOptions options;
  options.config = dir / "small.yaml";
  options.out = dir / "small.svg";
  options.page = "a4";
  const TargetPage drawing = WriteTargetPage(options);
  EXPECT_FALSE(drawing.turned);
  const std::string svg = test::ReadText(options.out);
  EXPECT_EQ(svg, TargetSvg(drawing));
  ExpectStripesMatch(svg, SmallTarget(), 210.0, 297.0, false);
  EXPECT_TRUE(test::TempFilesIn(dir.path()).empty());
}

// config/four-line-*.yaml draw exactly the built-ins; the 2 m boards' files need --page full.
TEST(TargetCommand, ShippedConfigsDrawTheBuiltInTargets) {
  test::TestDir dir;
  const std::string config_dir = std::string(OAL_SOURCE_DIR) + "/config/";
  for (const SheetCase& sheet : kSheetCases) {
    SCOPED_TRACE(sheet.page);
    TargetCommandOptions options;
    options.config = config_dir + "four-line-" + sheet.page + ".yaml";
    options.page = sheet.page;
    options.landscape = true;
    options.out = dir / (std::string(sheet.page) + ".svg");
    WriteTargetPage(options);
    ExpectStripesMatch(test::ReadText(options.out), sheet.target(), sheet.long_mm, sheet.short_mm,
                       false);
  }
  TargetCommandOptions options;
  options.config = config_dir + "four-line-board.yaml";
  options.out = dir / "board.svg";
  EXPECT_THROW(WriteTargetPage(options), TargetDoesNotFit);
  options.page = "full";
  WriteTargetPage(options);
  ExpectStripesMatch(test::ReadText(options.out), FourLineTarget(), 2020.0, 2020.0, false);
  options.config = config_dir + "two-line-target.yaml";
  options.out = dir / "two.svg";
  WriteTargetPage(options);
  ExpectStripesMatch(test::ReadText(options.out), TwoLineTarget(), 2020.0, 2020.0, false);
}

// Refused: nothing is written, and a file already there is left as it was.
TEST(TargetCommand, RefusalWritesNothingAndLeavesAFileAlone) {
  test::TestDir dir;
  TargetCommandOptions options;
  options.target = "four-line-board";
  options.page = "a4";
  options.out = dir / "board.svg";
  EXPECT_THROW(WriteTargetPage(options), TargetDoesNotFit);
  EXPECT_TRUE(fs::is_empty(dir.path()));
  test::WriteText(options.out, "the previous file\n");
  EXPECT_THROW(WriteTargetPage(options), TargetDoesNotFit);
  EXPECT_EQ(test::ReadText(options.out), "the previous file\n");
  EXPECT_TRUE(test::TempFilesIn(dir.path()).empty());
}

TEST(TargetCommand, BadOutputDirectoryIsAClearErrorAndLeavesNothing) {
  test::TestDir dir;
  TargetCommandOptions options;
  options.out = dir / "missing/target.svg";
  try {
    WriteTargetPage(options);
    FAIL() << "no error";
  } catch (const std::runtime_error& error) {
    EXPECT_THAT(error.what(), HasSubstr("--out"));
    EXPECT_THAT(error.what(), HasSubstr("missing"));
    EXPECT_THAT(error.what(), HasSubstr("does not exist"));
  }
  fs::create_directory(dir / "folder.svg");
  options.out = dir / "folder.svg";  // a directory
  EXPECT_THROW(WriteTargetPage(options), std::runtime_error);
  fs::remove(dir / "folder.svg");
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(TargetCommand, ThePdfIsOnePageOfTheSheetsSizeAndOtherExtensionsAreRefused) {
  test::TestDir dir;
  TargetCommandOptions options;
  options.out = dir / "a3.PDF";
  const TargetPage page = WriteTargetPage(options);
  const std::string pdf = test::ReadText(dir / "a3.PDF");
  EXPECT_EQ(pdf.rfind("%PDF-", 0), 0u);
  // One page, A3 portrait in points (297 x 420 mm), named in the title.
  EXPECT_EQ(Count(pdf, "/Type /Page\n") + Count(pdf, "/Type /Page "), 1);
  const std::size_t box = pdf.find("/MediaBox [");
  ASSERT_NE(box, std::string::npos);
  std::istringstream corners(pdf.substr(box + 11, 80));
  double x0 = -1, y0 = -1, x1 = 0, y1 = 0;
  corners >> x0 >> y0 >> x1 >> y1;
  EXPECT_EQ(x0, 0.0);
  EXPECT_EQ(y0, 0.0);
  EXPECT_NEAR(x1, 297.0 / 25.4 * 72.0, 1e-3);
  EXPECT_NEAR(y1, 420.0 / 25.4 * 72.0, 1e-3);
  EXPECT_THAT(pdf, HasSubstr("oalservo target four-line-a3, A3 portrait"));
  EXPECT_EQ(page.page, "A3 portrait");
  // The extension names the format: anything else is refused and nothing is written.
  for (const char* name : {"a3.png", "a3", "a3.svg.txt"}) {
    options.out = dir / name;
    try {
      WriteTargetPage(options);
      FAIL() << name << ": no error";
    } catch (const std::invalid_argument& error) {
      EXPECT_THAT(error.what(), HasSubstr("--out " + (dir / name)));
      EXPECT_THAT(error.what(), HasSubstr(".pdf (to print) or .svg"));
    }
    EXPECT_FALSE(fs::exists(dir / name)) << name;
  }
}

TEST(TargetCommand, BadConfigNamesTheFile) {
  test::TestDir dir;
  test::WriteText(dir / "bad.yaml", "target:\n  name: five-line\n");
  TargetCommandOptions options;
  options.config = dir / "bad.yaml";
  options.out = dir / "t.svg";
  try {
    WriteTargetPage(options);
    FAIL() << "no error";
  } catch (const std::runtime_error& error) {
    EXPECT_THAT(error.what(), HasSubstr(dir / "bad.yaml:2: 'target.name' = 'five-line'"));
  }
  EXPECT_FALSE(fs::exists(dir / "t.svg"));
}

// The binary, as a user runs it.
int RunTargetBinary(const std::string& arguments, const std::string& err_file) {
  const std::string command =
      std::string("'") + OAL_OALSERVO_PATH + "' target " + arguments + " 2>'" + err_file + "'";
  const int status = std::system(command.c_str());
  EXPECT_TRUE(WIFEXITED(status)) << command;
  return WEXITSTATUS(status);
}

TEST(TargetCommand, BinaryWritesTheA3SheetByDefault) {
  test::TestDir dir;
  ASSERT_EQ(RunTargetBinary("--out '" + (dir / "t.svg") + "'", dir / "err.txt"), 0);
  const std::string err = test::ReadText(dir / "err.txt");
  EXPECT_THAT(err, HasSubstr("oalservo target: " + (dir / "t.svg") +
                             " written (A3 portrait, 297 x 420 mm)"));
  EXPECT_THAT(err, HasSubstr("'four-line-a3' (board 420 x 297 mm) is drawn turned by 90 degrees"));
  EXPECT_THAT(err, HasSubstr("or lay it out on a landscape page to have it upright (--landscape)"));
  const std::string svg = test::ReadText(dir / "t.svg");
  ExpectPage(svg, 297.0, 420.0);
  ExpectStripesMatch(svg, FourLineA3Target(), 297.0, 420.0, true);

  ASSERT_EQ(
      RunTargetBinary("--page a4 --landscape --out '" + (dir / "a4.svg") + "'", dir / "err.txt"),
      0);
  EXPECT_THAT(test::ReadText(dir / "err.txt"), Not(HasSubstr("turned")));
  ExpectStripesMatch(test::ReadText(dir / "a4.svg"), FourLineA4Target(), 297.0, 210.0, false);

  ASSERT_EQ(
      RunTargetBinary("--target four-line-board --page full --out '" + (dir / "board.svg") + "'",
                      dir / "err.txt"),
      0);
  ExpectPage(test::ReadText(dir / "board.svg"), 2020.0, 2020.0);
}

TEST(TargetCommand, BinaryRefusesABoardLargerThanThePage) {
  test::TestDir dir;
  test::WriteText(dir / "board.svg", "the previous file\n");
  EXPECT_EQ(
      RunTargetBinary("--target four-line-board --page a3 --out '" + (dir / "board.svg") + "'",
                      dir / "err.txt"),
      1);
  const std::string err = test::ReadText(dir / "err.txt");
  EXPECT_THAT(err, HasSubstr("oalservo target: error: target 'four-line-board' (board 2000 x "
                             "2000 mm) does not fit on the A3 page"));
  EXPECT_THAT(err, HasSubstr("--page a3 without --target or --config prints four-line-a3"));
  EXPECT_THAT(err, HasSubstr("--page full"));
  EXPECT_EQ(test::ReadText(dir / "board.svg"), "the previous file\n");
  EXPECT_EQ(RunTargetBinary("--target four-line-board --out '" + (dir / "new.svg") + "'",
                            dir / "err.txt"),
            1);
  EXPECT_FALSE(fs::exists(dir / "new.svg"));
  EXPECT_TRUE(test::TempFilesIn(dir.path()).empty());
  // A bad --target is an error naming it (1); a page that is not a choice, a usage error (2).
  EXPECT_EQ(RunTargetBinary("--target six-line --out '" + (dir / "x.svg") + "'", dir / "err.txt"),
            1);
  EXPECT_THAT(test::ReadText(dir / "err.txt"), HasSubstr("--target = six-line"));
  EXPECT_EQ(RunTargetBinary("--page a5 --out '" + (dir / "x.svg") + "'", dir / "err.txt"), 2);
  EXPECT_EQ(RunTargetBinary("--target two-line --config x.yaml --out '" + (dir / "x.svg") + "'",
                            dir / "err.txt"),
            2);
  EXPECT_FALSE(fs::exists(dir / "x.svg"));
}

TEST(TargetCommand, BinaryHelpHasAnExampleForEachCase) {
  test::TestDir dir;
  const std::string help =
      std::string("'") + OAL_OALSERVO_PATH + "' target --help >'" + (dir / "help.txt") + "'";
  ASSERT_EQ(std::system(help.c_str()), 0);
  const std::string text = test::ReadText(dir / "help.txt");
  EXPECT_THAT(text, HasSubstr("oalservo target --out four-line-a3.pdf\n"));
  EXPECT_THAT(text, HasSubstr("oalservo target --page a3 --landscape --out four-line-a3.svg\n"));
  EXPECT_THAT(text, HasSubstr("oalservo target --page a4 --landscape --out four-line-a4.svg\n"));
  EXPECT_THAT(text, HasSubstr("--target four-line-board --page full --out"));
  EXPECT_THAT(text, HasSubstr("--config my-target.yaml --page a4"));
  for (const std::string& name : TargetNames()) EXPECT_THAT(text, HasSubstr(name));
  EXPECT_THAT(text, HasSubstr("--landscape"));
}

// `oalservo render --config FILE` renders the config's target and names it in the truth.
TEST(TargetCommand, RenderTakesTheTargetFromAConfig) {
  test::TestDir dir;
  test::WriteText(dir / "desk.yaml",
                  "target:\n  name: desk\n  board_width_m: 0.6\n  board_height_m: 0.6\n"
                  "  lines:\n"
                  "    - {from: [-0.05, -0.3], to: [-0.05, 0.3], width: 0.02}\n"
                  "    - {from: [-0.3, 0.02], to: [0.3, 0.02], width: 0.01}\n"
                  "    - {from: [-0.3, -0.3], to: [0.3, 0.3], width: 0.01}\n");
  RenderCommandOptions options;
  options.config = dir / "desk.yaml";
  options.target = "ignored-with-a-config";
  options.count = 1;
  options.width = 64;
  options.height = 48;
  options.fx_px = 60.0;
  options.out_dir = dir / "data";
  ASSERT_EQ(RenderDataset(options), 1);
  const auto truth = nlohmann::json::parse(test::ReadText(dir / "data/frame_0000.json"));
  EXPECT_EQ(truth["target"], "desk");
  EXPECT_EQ(truth["lines"].size(), 3u);
}

}  // namespace
}  // namespace oal
