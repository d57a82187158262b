#include "sim/runner/cli.h"

#include <filesystem>
#include <iostream>

#include "sim/runner/files.h"
#include "sim/runner/report.h"
#include "sim/runner/scenario.h"
#include "sim/runner/simulation.h"
#include "sim/world/track.h"

namespace paddock::runner {
namespace {

const char* kUsage =
    "usage:\n"
    "  paddock run SCENARIO.ini [--set section.key=value]... [--out DIR] [--json] [--quiet]\n"
    "      runs a scenario headless and prints the result; writes DIR/summary.json,\n"
    "      DIR/scenario.ini (resolved, defaults included) and DIR/log.csv\n"
    "      (DIR defaults to runs/<scenario name>). --json prints the summary as JSON;\n"
    "      --quiet prints only failed expectations. Exit 3 when [expect] fails.\n"
    "  paddock check-track FILE...\n"
    "      loads, validates and describes track CSV files\n";

// track files: the only place the program reads them
world::TrackModel load_track(const std::string& path, std::vector<std::string>* warnings) {
  world::TrackFile file = load_track_file(path);
  if (warnings) *warnings = file.warnings;
  return world::build_track(file);
}

int cmd_run(const std::vector<std::string>& args) {
  std::string scenario_path, out_dir;
  std::vector<std::string> overrides;
  bool json = false, quiet = false;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&](const char* flag) -> std::string {
      if (i + 1 >= args.size()) throw UserError(std::string(flag) + " needs a value");
      return args[++i];
    };
    if (a == "--set") overrides.push_back(value("--set"));
    else if (a.rfind("--set=", 0) == 0) overrides.push_back(a.substr(6));
    else if (a == "--out") out_dir = value("--out");
    else if (a == "--json") json = true;
    else if (a == "--quiet") quiet = true;
    else if (!a.empty() && a[0] == '-') throw UserError("unknown option " + a + "\n" + kUsage);
    else if (scenario_path.empty()) scenario_path = a;
    else throw UserError("more than one scenario given: " + scenario_path + " and " + a);
  }
  if (scenario_path.empty()) throw UserError(std::string("run needs a scenario file\n") + kUsage);

  const Scenario sc = load_scenario(scenario_path, overrides);
  std::vector<std::string> warnings;
  const world::TrackModel track = load_track(sc.track_path, &warnings);
  for (const auto& w : warnings) std::cerr << "warning: " << w << "\n";
  if (out_dir.empty()) out_dir = (std::filesystem::path("runs") / sc.name).string();

  const RunResult result = run(sc, track);
  const auto failed = check_expectations(sc.expect, result);
  const std::string js = summary_json(sc, result, failed);
  write_file_atomic(out_dir + "/scenario.ini", resolved_ini(sc));
  write_file_atomic(out_dir + "/log.csv", log_csv(result.log));
  write_file_atomic(out_dir + "/summary.json", js);

  if (json) std::cout << js;
  else if (!quiet || !failed.empty()) std::cout << summary_text(sc, result, failed) << "  output      " << out_dir << "/\n";
  return failed.empty() ? 0 : 3;
}

int cmd_check_track(const std::vector<std::string>& args) {
  if (args.empty()) throw UserError(std::string("check-track needs at least one file\n") + kUsage);
  int bad = 0;
  for (const auto& path : args) {
    try {
      const world::TrackFile file = load_track_file(path);
      const world::TrackModel track = world::build_track(file);
      std::cout << world::check_track_report(track, file) << "\n";
    } catch (const std::exception& e) {
      std::cerr << "error: " << e.what() << "\n";
      ++bad;
    }
  }
  return bad == 0 ? 0 : 2;
}

}  // namespace

int run_cli(const std::vector<std::string>& args) {
  try {
    if (args.empty() || args[0] == "help" || args[0] == "--help" || args[0] == "-h") {
      std::cout << kUsage;
      return args.empty() ? 2 : 0;
    }
    const std::vector<std::string> rest(args.begin() + 1, args.end());
    if (args[0] == "run") return cmd_run(rest);
    if (args[0] == "check-track") return cmd_check_track(rest);
    throw UserError("unknown command '" + args[0] + "'\n" + kUsage);
  } catch (const std::exception& e) {
    // user errors (and track errors) carry their file:line already
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
}

}  // namespace paddock::runner
