#include "app/servo_accuracy_command.h"

#include <visp3/core/vpMath.h>
#include <visp3/core/vpRxyzVector.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/command_line.h"
#include "app/fault_campaign.h"
#include "app/servo_accuracy.h"
#include "app/servo_command.h"
#include "app/servo_output.h"
#include "base/statistics.h"
#include "io/atomic_file.h"

namespace oal {
namespace {

std::string Table(const ServoAccuracyReport& report) {
  std::ostringstream out;
  out << "| law | converged | moves median / p95 / max | true final error median / max | "
         "motion from an unconfirmed pose |\n"
      << "|---|---:|---:|---|---:|\n";
  for (const ServoAccuracyLaw& law : report.laws) {
    std::vector<double> moves, mm, deg;
    int unconfirmed = 0;
    for (const ServoAccuracyRun& run : law.runs) {
      unconfirmed += std::max(run.unconfirmed_motions, 0);
      if (run.status != ServoRunStatus::kConverged) continue;
      moves.push_back(run.moves);
      mm.push_back(run.final_translation_error_mm);
      deg.push_back(run.final_rotation_error_deg);
    }
    const int n = static_cast<int>(law.runs.size());
    out << std::fixed << "| " << ToString(law.mode) << " | " << law.converged() << " / " << n
        << " (" << std::setprecision(1) << 100.0 * law.converged() / n << " %) | "
        << std::setprecision(0) << Quantile(moves, 0.5) << " / " << Quantile(moves, 0.95) << " / "
        << Quantile(moves, 1.0) << " | " << std::setprecision(2) << Quantile(mm, 0.5) << " mm "
        << std::setprecision(3) << Quantile(deg, 0.5) << "° / " << std::setprecision(2)
        << Quantile(mm, 1.0) << " mm " << std::setprecision(3) << Quantile(deg, 1.0) << "° | "
        << unconfirmed << " |\n";
  }
  for (const ServoAccuracyLaw& law : report.laws) {
    for (const ServoAccuracyRun& run : law.runs) {
      if (run.status == ServoRunStatus::kConverged) continue;
      out << "- " << ToString(law.mode) << ", start " << run.start << " (" << std::setprecision(0)
          << run.start_distance_m * 1e3 << " mm, " << std::setprecision(1) << run.start_off_deg
          << "° from the goal): " << ToString(run.status) << ": " << run.message << '\n';
    }
  }
  return out.str();
}

nlohmann::json ToJson(const ServoAccuracyReport& report) {
  const ServoAccuracyOptions& o = report.options;
  nlohmann::json laws = nlohmann::json::array();
  for (const ServoAccuracyLaw& law : report.laws) {
    nlohmann::json runs = nlohmann::json::array();
    for (const ServoAccuracyRun& run : law.runs) {
      const vpRxyzVector rxyz(run.start_wMc.getRotationMatrix());
      const vpTranslationVector t = run.start_wMc.getTranslationVector();
      // The config's pose form: `robot: {start: ...}` re-runs this start alone.
      const nlohmann::json start_pose = {
          {"translation_m", {t[0], t[1], t[2]}},
          {"rxyz_deg", {vpMath::deg(rxyz[0]), vpMath::deg(rxyz[1]), vpMath::deg(rxyz[2])}}};
      runs.push_back({{"start", run.start},
                      {"robot_start", start_pose},
                      {"status", ToString(run.status)},
                      {"message", run.message},
                      {"moves", run.moves},
                      {"unconfirmed_motions", run.unconfirmed_motions},
                      {"start_distance_to_goal_m", run.start_distance_m},
                      {"start_rotation_to_goal_deg", run.start_off_deg},
                      {"final_true_translation_error_mm", run.final_translation_error_mm},
                      {"final_true_rotation_error_deg", run.final_rotation_error_deg}});
    }
    laws.push_back({{"law", ToString(law.mode)},
                    {"starts", law.runs.size()},
                    {"converged", law.converged()},
                    {"runs", runs}});
  }
  return {{"options",
           {{"starts", o.starts},
            {"seed", o.seed},
            {"min_distance_m", o.min_distance_m},
            {"max_distance_m", o.max_distance_m},
            {"max_off_deg", o.max_off_deg},
            {"max_iterations", o.max_iterations}}},
          {"laws", laws}};
}

}  // namespace

int RunServoAccuracy(int argc, char** argv) {
  CLI::App cli{
      "Closed-loop convergence of the servo loop from random start poses (fixed seed), image "
      "in the loop, for each law: starts 0.3-0.8 m from the target (a sheet's four crossings "
      "in view), up to 30 deg off; the target, the scene, the goal and the camera from the "
      "configuration (default: the built-in config/servo-sim.yaml: the A3 sheet on a bench).",
      "oalservo servo-accuracy"};
  ServoAccuracyOptions options;
  std::string config_path, out_path, target_name, background;
  std::vector<std::string> laws;
  cli.add_option("--config", config_path, "YAML configuration (as for oalservo servo)")
      ->check(CLI::ExistingFile);
  cli.add_option("--target", target_name,
                 "a built-in target instead of the configuration's (" + TargetNameList() + ")");
  cli.add_option("--background", background,
                 "image of the surface the target lies on, instead of the configuration's "
                 "scene.background");
  cli.add_option("--starts", options.starts, "random start poses per law, [1, 1000000]")
      ->capture_default_str();
  cli.add_option("--seed", options.seed, "seed of the start poses")->capture_default_str();
  cli.add_option("--min-distance", options.min_distance_m, "metres")->capture_default_str();
  cli.add_option("--max-distance", options.max_distance_m, "metres")->capture_default_str();
  cli.add_option("--max-off-deg", options.max_off_deg, "tilt and roll bound")
      ->capture_default_str();
  cli.add_option("--max-iterations", options.max_iterations,
                 "overrides servo.max_iterations (0: as configured)")
      ->capture_default_str();
  cli.add_option("--laws", laws, "laws to run (default: all three)")
      ->delimiter(',')
      ->check(CLI::IsMember({"point-and-go", "exponential", "velocity"}));
  cli.add_option("--out", out_path, "write the runs as JSON to this file");
  FaultCampaignOptions faults;
  int fault_runs = 0;
  cli.add_option("--faults", fault_runs,
                 "instead of convergence, the fault campaign: this many runs of the "
                 "configuration's servo job, each with one fault at a random moment (the "
                 "Scorbot's link, the drive, the frames), each checked for the robot stopped, "
                 "the reason printed, no motion after the stop, whole outputs; [1, 1000000]");
  cli.add_option("--time-scale", faults.time_scale,
                 "with --faults: simulated seconds per second of the Scorbot's controller "
                 "simulator, [0.01, 1000]")
      ->capture_default_str();
  cli.add_option("--jobs", faults.jobs,
                 "with --faults: runs at once (each mostly waits on the link), [1, 64]")
      ->capture_default_str();
  cli.add_option("--work-dir", faults.work_dir,
                 "with --faults: the runs' output folders run_NNNN (replaced); a run that passes "
                 "is removed, a failed one kept with its console log")
      ->capture_default_str();
  cli.footer(
      "Examples:\n"
      "  oalservo servo-accuracy --starts 100 --out out/servo-accuracy.json\n"
      "  oalservo servo-accuracy --config config/scorbot-sim.yaml --faults 1000 --out "
      "out/faults-scorbot.json\n"
      "  oalservo servo-accuracy --starts 100 --target four-line-board\n"
      "  oalservo servo-accuracy --starts 100 --background "
      "/usr/share/visp-images-data/ViSP-images/Klimt/Klimt.pgm");
  if (auto exit = ParseCommandLine(cli, argc, argv)) return *exit;
  if (!out_path.empty()) {
    // Before the runs, not after them: a directory that cannot take the file fails now.
    const std::filesystem::path parent = std::filesystem::path(out_path).parent_path();
    CheckWritableDirectory(parent.empty() ? "." : parent, "directory of --out");
    CheckOutputFile(out_path);
  }
  const bool fault_campaign = cli.count("--faults") > 0;
  if (fault_campaign) {
    faults.runs = fault_runs;
    faults.seed = options.seed;
    CheckInOptionWords([&] { faults.Check(); },
                       {{"FaultCampaignOptions::runs", "--faults"},
                        {"FaultCampaignOptions::time_scale", "--time-scale"},
                        {"FaultCampaignOptions::jobs", "--jobs"},
                        {"FaultCampaignOptions::work_dir", "--work-dir"}});
  }
  if (!laws.empty()) {
    options.modes.clear();
    for (const std::string& law : laws) options.modes.push_back(ServoModeFromString(law));
  }
  CheckInOptionWords([&] { options.Check(); },
                     {{"ServoAccuracyOptions::starts", "--starts"},
                      {"ServoAccuracyOptions::min_distance_m", "--min-distance"},
                      {"ServoAccuracyOptions::max_distance_m", "--max-distance"},
                      {"ServoAccuracyOptions::max_off_deg", "--max-off-deg"},
                      {"ServoAccuracyOptions::max_iterations", "--max-iterations"},
                      {"ServoAccuracyOptions::modes", "--laws"}});
  ServoCommandOptions servo;
  servo.config_path = config_path;
  ServoAppConfig config = LoadServoConfig(servo);
  if (!target_name.empty()) {
    try {
      config.target = TargetByName(target_name);
    } catch (const std::invalid_argument& error) {
      throw std::invalid_argument(std::string("--target: ") + error.what());
    }
  }
  if (!background.empty()) {
    config.scene.background = background;
    config.scene.background_origin = "--background";
    RenderOptions probe;
    config.scene.ApplyTo(&probe);  // an unreadable image fails now, not in the first run
  }
  if (fault_campaign) {
    const FaultCampaignReport report =
        RunFaultCampaign(config, faults, FrameProgress("fault run", 30.0, "runs"));
    std::cout << FaultCampaignTable(report);
    if (!out_path.empty()) WriteFileAtomically(out_path, FaultCampaignJson(report));
    return report.failed() == 0 ? kExitOk : kExitError;
  }
  const ServoAccuracyReport report =
      EvaluateServoAccuracy(config, options, FrameProgress("servo run", 30.0, "runs"));
  std::cout << Table(report);
  if (!out_path.empty()) {
    nlohmann::json json = ToJson(report);
    json["options"]["target"] = config.target.name;
    json["options"]["background"] = config.scene.background;
    json["options"]["config"] = config_path;
    WriteFileAtomically(out_path, json.dump(2) + '\n');
  }
  return kExitOk;
}

}  // namespace oal
