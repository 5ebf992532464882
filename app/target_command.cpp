#include "app/target_command.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/command_line.h"
#include "app/config.h"
#include "base/format.h"
#include "io/atomic_file.h"
#include "print/target_pdf.h"
#include "print/target_svg.h"

namespace oal {

namespace fs = std::filesystem;

void TargetCommandOptions::Check() const {
  if (!target.empty() && !config.empty()) {
    throw std::invalid_argument("--target " + target + " and --config " + config +
                                " both name a target: give one");
  }
  if (!target.empty()) {
    const std::vector<std::string>& names = TargetNames();
    if (target != "four-line" && std::find(names.begin(), names.end(), target) == names.end()) {
      throw std::invalid_argument("--target = " + target + ": it is one of " + TargetNameList());
    }
  }
  try {
    CheckPageName(page);
  } catch (const std::invalid_argument&) {
    throw std::invalid_argument("--page = " + page + ": it is one of a4, a3, letter, full");
  }
  if (landscape && page == "full") {
    throw std::invalid_argument(
        "--landscape is for a sheet (--page a4, a3 or letter): --page full is the board's own "
        "size and orientation");
  }
  if (out.empty()) throw std::invalid_argument("no output file given (--out FILE.pdf or FILE.svg)");
  const std::string extension = Lowercase(fs::path(out).extension().string());
  if (extension != ".pdf" && extension != ".svg") {
    throw std::invalid_argument("--out " + out +
                                ": the file's extension names its format: .pdf "
                                "(to print) or .svg (to edit or view)");
  }
}

LineTarget TargetToPrint(const TargetCommandOptions& options) {
  if (!options.target.empty()) return TargetByName(options.target);
  if (!options.config.empty()) return LoadConfig(options.config).target;
  return TargetByName(SheetTargetName(options.page));
}

namespace {

// The page, its refusal and its note in the command's words: which options print instead.
TargetPage DrawInCommandWords(const LineTarget& target, const TargetCommandOptions& options) {
  try {
    TargetPage page = DrawTargetPage(target, options.page, options.landscape);
    if (page.turned) page.note += " (--landscape)";
    return page;
  } catch (const TargetDoesNotFit& refused) {
    const TargetDoesNotFit::Alternatives& instead = refused.alternatives();
    std::string message = refused.what();
    message = message.substr(0, message.find(" Instead: ")) +
              " Instead: print the target made for this sheet (--page " + instead.page +
              " without --target or --config prints " + instead.page_target + ")";
    std::string larger;
    for (const std::string& sheet : instead.larger) {
      larger += std::string(larger.empty() ? "" : " or ") + "--page " + sheet;
    }
    if (!larger.empty()) message += ", or a page that holds this one (" + larger + ")";
    message += ", or this target at its full size with --page full (" +
               Number(instead.full_width_mm) + " x " + Number(instead.full_height_mm) +
               " mm, for a plotter or a print shop)";
    throw TargetDoesNotFit(message, instead);
  }
}

}  // namespace

TargetPage WriteTargetPage(const TargetCommandOptions& options) {
  options.Check();
  const fs::path out(options.out);
  const fs::path dir = out.parent_path();
  if (!dir.empty() && !fs::is_directory(dir)) {
    throw std::runtime_error("cannot write --out " + options.out + ": directory '" + dir.string() +
                             "' does not exist");
  }
  if (fs::is_directory(out)) {
    throw std::runtime_error("cannot write --out " + options.out + ": it is a directory");
  }
  const TargetPage page = DrawInCommandWords(TargetToPrint(options), options);
  const bool pdf = Lowercase(out.extension().string()) == ".pdf";
  WriteFileAtomically(out, pdf ? TargetPdf(page) : TargetSvg(page));
  return page;
}

int RunTarget(int argc, char** argv) {
  TargetCommandOptions options;
  const std::string names = TargetNameList();
  CLI::App cli(
      "Write a printable, true-scale page of a line target: a PDF (--out x.pdf, to print at "
      "100 %) or an SVG (--out x.svg, 1 unit = 1 mm): the "
      "stripes in black, and, small and grey and at least 5 mm clear of every stripe and of the "
      "page's edge, the line numbers, the target's name, \"print at 100 %, do not scale\" and a "
      "100 mm scale bar. Without --target or --config it prints the sheet target made for the "
      "page (a4: four-line-a4, a3: four-line-a3, letter: four-line-letter). The page is "
      "portrait unless --landscape; a board that fits it only turned by 90 degrees is drawn "
      "turned (the same print). A board larger than the page is refused (nothing is "
      "written); --page full prints it at its full size.",
      "oalservo target");
  CLI::Option* target = cli.add_option("--target", options.target,
                                       "a built-in target: " + names +
                                           " (four-line is an older "
                                           "name of four-line-board)");
  cli.add_option("--config", options.config,
                 "YAML file whose 'target:' section gives the target (config/four-line-a3.yaml "
                 "and the other config/four-line-*.yaml are the built-ins written out)")
      ->excludes(target)
      ->check(CLI::ExistingFile);
  cli.add_option("--page", options.page,
                 "a4 (210 x 297 mm), a3 (297 x 420 mm), letter (215.9 x 279.4 mm), or full: the "
                 "board at its full size with 10 mm around it, for a plotter or a print shop")
      ->check(CLI::IsMember({"a4", "a3", "letter", "full"}))
      ->capture_default_str();
  cli.add_flag("--landscape", options.landscape,
               "the page's long side across (a4, a3, letter): the sheet targets print upright");
  cli.add_option("--out", options.out, "the file to write: .pdf (to print) or .svg")->required();
  cli.footer(
      "Examples:\n"
      "  oalservo target --out four-line-a3.pdf\n"
      "      four-line-a3 on an A3 page, to print (portrait: drawn turned, the same print)\n"
      "  oalservo target --page a3 --landscape --out four-line-a3.svg\n"
      "      the same, upright on a landscape A3 page\n"
      "  oalservo target --page a4 --landscape --out four-line-a4.svg\n"
      "      four-line-a4 on an A4 sheet (--page letter: four-line-letter on US letter)\n"
      "  oalservo target --target four-line-board --page full --out four-line-board.svg\n"
      "      the 2 m x 2 m board (the paper's condition) at its full size, for a plotter\n"
      "  oalservo target --config my-target.yaml --page a4 --out mine.svg\n"
      "      a target of your own (its target: section); refused if its board does not fit\n\n"
      "Print at 100 % (no \"fit to page\") and check the scale bar with a ruler: the pose takes "
      "the target's lengths as printed.");
  if (const auto exit = ParseCommandLine(cli, argc, argv)) return *exit;
  const TargetPage drawing = WriteTargetPage(options);
  if (!drawing.warning.empty()) Warn("target", drawing.warning);
  std::cerr << "oalservo target: " << options.out << " written (" << drawing.page << ", "
            << Number(drawing.page_width_mm) << " x " << Number(drawing.page_height_mm) << " mm)\n";
  if (drawing.turned) std::cerr << "oalservo target: " << drawing.note << '\n';
  return kExitOk;
}

}  // namespace oal
