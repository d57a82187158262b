#include "sim/runner/cli.h"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <optional>
#include <tuple>

#include "autonomy/common/format.h"
#include "autonomy/common/workers.h"
#include "render/figures.h"
#include "sim/runner/bench_compare.h"
#include "sim/runner/files.h"
#include "sim/runner/plots.h"
#include "sim/runner/limit_report.h"
#include "sim/runner/replay.h"
#include "sim/runner/reports.h"
#include "sim/runner/run_log.h"
#include "sim/runner/report.h"
#include "sim/runner/scenario.h"
#include "sim/runner/schema.h"
#include "sim/runner/simulation.h"
#include "sim/runner/sweep.h"
#include "sim/runner/sweep_report.h"
#include "sim/runner/tune.h"
#include "sim/runner/vehicle_report.h"
#include "sim/world/track.h"

namespace paddock::runner {
namespace {

const char* kUsage =
    "usage:\n"
    "  paddock run SCENARIO.ini [--set section.key=value]... [--out DIR] [--json] [--quiet] [--log]\n"
    "              [--profile] [--threads N] [--plots [PLOT OPTIONS]]\n"
    "      runs a scenario headless and prints the result; writes DIR/summary.json,\n"
    "      DIR/scenario.ini (resolved, defaults included) and DIR/log.csv\n"
    "      (DIR defaults to runs/<scenario name> in the current folder). --json prints\n"
    "      the summary as JSON; --quiet prints only failed expectations; --plots also\n"
    "      draws the figures;\n"
    "      --log writes DIR/run.mcap (a wire run: the LiDAR's packets, the CAN frames,\n"
    "      the stack's outputs in Foxglove's schemas).\n"
    "      --profile prints where the wall time went, by stage (physics, lidar,\n"
    "      camera, perception, localisation, planning, control, logging, scoring,\n"
    "      other; also in summary.json's \"profile\" always).\n"
    "      --threads N runs on N threads, the same result: the camera renders beside\n"
    "      the LiDAR's cast (--set sim.threads=2); with a perception latency the scans\n"
    "      are processed beside the loop (--set perception.threads=2) and FastSLAM's\n"
    "      particles are split N - 1 ways, else N ways (--set slam.threads=N); a sweep\n"
    "      keeps one run per core.\n"
    "      Exit 3 when [expect] fails.\n"
    "  paddock bench-compare OLD.json NEW.json   (./paddock bench compare OLD.json NEW.json)\n"
    "      two runs of the benchmarks (./paddock bench --json FILE) side by side: each\n"
    "      one's CPU time per iteration and NEW/OLD, SLOWER past 1.10 (then exit 1)\n"
    "  paddock replay LOG.mcap [--set section.key=value]... [--from S] [--until S] [--profile]\n"
    "                [--threads N]\n"
    "      reruns the stack on a run's log (paddock run ... --log) without the simulator:\n"
    "      the recorded packets and frames through the car's decoders. Unchanged it gives\n"
    "      the live run's commands bit for bit; with --set it says where they differ.\n"
    "      --profile prints where the wall time went, by stage (logging: reading the\n"
    "      log; lidar: decoding its packets; the stack's stages as in a run).\n"
    "      --threads 2 reads the log, and runs the LiDAR pipeline on its scans, on a\n"
    "      second thread, the same result (the stack takes a scan's result only when\n"
    "      it was computed on its own inputs, bit for bit).\n"
    "  paddock car SCENARIO.ini [--set section.key=value]... [--log] [--out DIR]\n"
    "      the car binary: the scenario's stack alone behind the car's sockets ([car]:\n"
    "      the LiDAR's UDP packets, the CAN bus by SocketCAN or CAN over UDP, the\n"
    "      detector node's boxes), with its watchdogs. clock = lockstep runs with\n"
    "      paddock run ... --set hal.transport=udp (software in the loop); clock = wall\n"
    "      runs on the car. Stops at the simulator's end, or on SIGINT/SIGTERM. --log\n"
    "      writes DIR/run.mcap (DIR defaults to runs/car_<scenario name>), which\n"
    "      paddock replay reruns\n"
    "  paddock sweep SWEEP.ini [--jobs N] [--out DIR] [--resume] [--shard i/n] [--plots]\n"
    "      runs a sweep's points (scenarios x [vary] values x seeds) on N cores (default:\n"
    "      all) into DIR (default runs/<sweep name>): DIR/points/NNNN/{scenario.ini,\n"
    "      summary.json}, DIR/results.csv (one row per point), DIR/timing.csv.\n"
    "      --resume runs only the points an interrupted sweep left; --shard runs the\n"
    "      i-th of n slices of the points (a Slurm task). Exit 1 if a point failed to\n"
    "      run, 130 if interrupted\n"
    "  paddock sweep SWEEP.ini --slurm [--partition P] [--time T] [--array-limit K]\n"
    "              [--tasks N] [--cpus-per-task C] [--sbatch-arg ARG]... [--dry-run | --wait]\n"
    "      writes DIR/slurm/sweep.sbatch (an array job, one shard per task) and submits\n"
    "      it with sbatch; --wait waits for it and collects\n"
    "  paddock sweep collect DIR\n"
    "      DIR/results.csv and timing.csv from the points' summaries (after Slurm)\n"
    "  paddock sweep report DIR [--top N]\n"
    "      the best N configurations (mean over scenarios and seeds) as Markdown, and\n"
    "      the best one's lines to paste\n"
    "  paddock sweep plot DIR [PLOT OPTIONS]   (or --plots on a local sweep)\n"
    "      DIR/plots/: total time against each numeric key, the heat map of the first\n"
    "      two, the Pareto front of total time against tracking RMS\n"
    "  paddock tune TUNE.ini [--jobs N] [--out DIR] [--max-evals N]\n"
    "      optimises the [optimise] keys within their bounds (NLopt) for the weighted\n"
    "      total cost of the [tune] scenarios' runs; writes DIR/evaluations.csv and\n"
    "      DIR/best.ini (DIR defaults to runs/<tune name>)\n"
    "  paddock plot RUN_DIR [PLOT OPTIONS]\n"
    "      draws DIR/map.png, DIR/controller.png and DIR/laps.png from a finished\n"
    "      run's scenario.ini, log.csv and summary.json\n"
    "  plot options: --map-size N (px, default 1600), --chart-size WxH (default\n"
    "      1600x1200), --dpi D (default 150: text and lines are sized in points)\n"
    "  paddock report controllers SCENARIO.ini [--set section.key=value]...\n"
    "      Table I of the paper: the scenario with each lateral controller, as Markdown\n"
    "  paddock report smoothing TRACK.csv\n"
    "      Table II of the paper: four smoothings of the track's planned centreline\n"
    "  paddock report vehicle [CAR.ini] [--out DIR] [--chart-size WxH] [--dpi D]\n"
    "      the car's figures from experiments on the simulated car: 0-75 m, top speed,\n"
    "      braking from 100 km/h, the skidpad limit and the g-g-v envelope; writes\n"
    "      DIR/vehicle_report.json and DIR/ggv.png (CAR.ini defaults to the paddock\n"
    "      tree's scenarios/vehicles/default.ini, DIR to runs/vehicle_<car name>)\n"
    "  paddock report limit SCENARIO.ini [--clearance M] [--set section.key=value]...\n"
    "              [--out DIR] [--map-size N] [--dpi D]\n"
    "      the fastest flying lap the scenario's car can drive on its circuit: its\n"
    "      g-g-v measured on the model, a QSS forward-backward profile on the\n"
    "      centreline and on the minimum-curvature line M m (default 1) from the\n"
    "      boundaries; writes DIR/limit_report.json, DIR/limit_lines.csv (both lines'\n"
    "      samples) and DIR/limit.png (DIR defaults to runs/limit_<scenario name>)\n"
    "  paddock keys\n"
    "      every scenario key (section = struct path) with its default, unit, range and\n"
    "      meaning, as the README's Markdown table\n"
    "  paddock check-track FILE...\n"
    "      loads, validates and describes track CSV files\n";

// track files: the only place the program reads them
world::TrackModel load_track(const std::string& path, std::vector<std::string>* warnings) {
  world::TrackFile file = load_track_file(path);
  if (warnings) *warnings = file.warnings;
  return world::build_track(file);
}

// a whole number in [lo, hi] from an option's value
int option_int(const std::string& flag, const std::string& v, int lo, int hi) {
  char* end = nullptr;
  const long x = std::strtol(v.c_str(), &end, 10);
  if (v.empty() || *end != '\0' || x < lo || x > hi) {
    throw UserError(flag + " " + v + ": expected a whole number from " + std::to_string(lo) + " to " + std::to_string(hi));
  }
  return static_cast<int>(x);
}


// Ctrl-C (or a kill) during a run: the process ends at once, 128 + the signal,
// saying that the output folder is marked incomplete (the marker stays)
char g_interrupt_message[1024];
std::size_t g_interrupt_length = 0;
extern "C" void on_run_interrupt(int sig) {
  const ssize_t w = ::write(2, g_interrupt_message, g_interrupt_length);
  (void)w;
  ::_exit(128 + sig);
}
void announce_interrupts(const std::string& marker) {
  const std::string m = "paddock: interrupted; " + marker + " marks the run's folder incomplete\n";
  g_interrupt_length = std::min(m.size(), sizeof g_interrupt_message);
  std::copy(m.begin(), m.begin() + static_cast<std::ptrdiff_t>(g_interrupt_length), g_interrupt_message);
  struct sigaction sa {};
  sa.sa_handler = on_run_interrupt;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

// takes a plot option at args[i] (and its value); false when args[i] is not one
bool plot_option(const std::vector<std::string>& args, std::size_t& i, PlotOptions& o) {
  const std::string& a = args[i];
  if (a != "--map-size" && a != "--chart-size" && a != "--dpi") return false;
  if (i + 1 >= args.size()) throw UserError(a + " needs a value");
  const std::string v = args[++i];
  if (a == "--map-size") {
    o.map_size = option_int(a, v, 200, 10000);
  } else if (a == "--chart-size") {
    const auto x = v.find('x');
    if (x == std::string::npos) throw UserError(a + " " + v + ": expected WIDTHxHEIGHT, e.g. 1600x1200");
    o.chart_width = option_int(a, v.substr(0, x), 200, 10000);
    o.chart_height = option_int(a, v.substr(x + 1), 200, 10000);
  } else {
    o.dpi = option_int(a, v, 30, 1200);
  }
  return true;
}

int cmd_run(const std::vector<std::string>& args) {
  std::string scenario_path, out_dir;
  std::vector<std::string> overrides;
  bool json = false, quiet = false, plots = false, log = false, profile = false;
  std::optional<int> threads;
  std::size_t threads_at = 0;
  PlotOptions plot_options;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&](const char* flag) -> std::string {
      if (i + 1 >= args.size()) throw UserError(std::string(flag) + " needs a value");
      return args[++i];
    };
    if (plot_option(args, i, plot_options)) continue;
    if (a == "--plots") plots = true;
    else if (a == "--set") overrides.push_back(value("--set"));
    else if (a.rfind("--set=", 0) == 0) overrides.push_back(a.substr(6));
    else if (a == "--out") out_dir = value("--out");
    else if (a == "--json") json = true;
    else if (a == "--quiet") quiet = true;
    else if (a == "--log") log = true;
    else if (a == "--profile") profile = true;
    else if (a == "--threads") {
      // the run on N threads (thread_overrides), in the overrides' order
      // once the scenario is known
      threads = option_int("--threads", value("--threads"), 1, Workers::kMaxThreads);
      threads_at = overrides.size();
    }
    else if (!a.empty() && a[0] == '-') throw UserError("unknown option " + a + "\n" + kUsage);
    else if (scenario_path.empty()) scenario_path = a;
    else throw UserError("more than one scenario given: " + scenario_path + " and " + a);
  }
  if (scenario_path.empty()) throw UserError(std::string("run needs a scenario file\n") + kUsage);
  if (threads) {
    const std::vector<std::string> t = thread_overrides(*threads, load_scenario(scenario_path, overrides));
    overrides.insert(overrides.begin() + static_cast<std::ptrdiff_t>(threads_at), t.begin(), t.end());
  }

  const Scenario scenario = load_scenario(scenario_path, overrides);
  std::vector<std::string> warnings;
  const world::TrackModel track = load_track(scenario.track_path, &warnings);
  for (const auto& w : warnings) std::cerr << "warning: " << w << "\n";
  if (out_dir.empty()) out_dir = (std::filesystem::path("runs") / scenario.name).string();
  // DIR/INCOMPLETE until every result is in place (and the folder's
  // writability checked before the work); Ctrl-C leaves it, and says so
  IncompleteMarker marker(out_dir, "paddock run " + scenario_path + " started here");
  announce_interrupts(marker.path());

  // --log: DIR/run.mcap, written beside the run and put in place at its end
  std::unique_ptr<RunLog> run_log;
  if (log) {
    std::filesystem::create_directories(out_dir);
    run_log = std::make_unique<RunLog>(out_dir + "/run.mcap", scenario);
  }
  const RunResult result = run_log ? run(scenario, track, {run_log.get()}, run_log.get()) : run(scenario, track);
  if (run_log) run_log->close();
  const auto failed = check_expectations(scenario.expect, result);
  const std::string js = summary_json(scenario, result, failed);
  write_file_atomic(out_dir + "/scenario.ini", resolved_ini(scenario));
  write_file_atomic(out_dir + "/log.csv", log_csv(result.log));
  write_file_atomic(out_dir + "/plan.json", plan_json(result));
  if (result.limit) write_file_atomic(out_dir + "/limit_lines.csv", limit_lines_csv(*result.limit));
  if (scenario.autonomy.slam != stack::SlamMode::GroundTruth) {
    write_file_atomic(out_dir + "/slam.csv", slam_csv(result.slam.series));
  } else {
    std::filesystem::remove(out_dir + "/slam.csv");  // a earlier run's in the same place would be drawn
  }
  write_file_atomic(out_dir + "/summary.json", js);
  if (result.snapshot) {
    write_file_atomic(out_dir + "/perception.json", perception_json(*result.snapshot));
    if (result.snapshot->camera) {
      const PerceptionSnapshot& s = *result.snapshot;
      render::Image img;
      img.width = s.width;
      img.height = s.height;
      img.rgba.resize(static_cast<std::size_t>(s.width) * static_cast<std::size_t>(s.height) * 4, 255);
      for (std::size_t i = 0; i < s.rgb.size() / 3; ++i)
        for (std::size_t c = 0; c < 3; ++c) img.rgba[4 * i + c] = s.rgb[3 * i + c];
      write_png(out_dir + "/camera.png", img);
    }
  }

  std::vector<std::string> figures;
  if (plots) figures = plot_run(out_dir, plot_options);
  marker.done();

  if (json) {
    std::cout << js;
  } else if (!quiet || !failed.empty()) {
    std::cout << summary_text(scenario, result, failed) << "  output      " << out_dir << "/\n";
    for (const auto& f : figures) std::cout << "  figure      " << f << "\n";
  }
  if (profile && !json) std::cout << "\nwhere the wall time went (--profile):\n" << profile_text(result);
  return failed.empty() ? 0 : 3;
}

// report vehicle [CAR.ini] [--out DIR] [--chart-size WxH] [--dpi D]
int cmd_report_vehicle(const std::vector<std::string>& args) {
  std::string car, out_dir;
  PlotOptions options;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a != "--map-size" && plot_option(args, i, options)) continue;
    if (a == "--out") {
      if (i + 1 >= args.size()) throw UserError("--out needs a value");
      out_dir = args[++i];
    } else if (!a.empty() && a[0] == '-') {
      throw UserError("report vehicle: unknown option " + a + "\n" + kUsage);
    } else if (car.empty()) {
      car = a;
    } else {
      throw UserError("report vehicle: more than one vehicle file given: " + car + " and " + a);
    }
  }
  // the default: the paddock tree's own car, wherever the command is run
  if (car.empty()) car = std::string(PADDOCK_SOURCE_DIR) + "/scenarios/vehicles/default.ini";
  const vehicle::VehicleParams params = load_vehicle_file(car);
  // like run's runs/<scenario name>
  if (out_dir.empty()) out_dir = "runs/vehicle_" + std::filesystem::path(car).stem().string();
  const auto start = std::chrono::steady_clock::now();
  const VehicleReport report = vehicle_report(params, car);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::vector<std::string> files = write_vehicle_report(report, out_dir, options);
  std::cout << vehicle_report_text(report) << "  output      " << files[0] << "\n  figure      " << files[1] << "\n"
            << "  speed       " << fixed(report.simulated_time, 1) << " s simulated in " << fixed(wall, 3) << " s\n";
  return 0;
}

// report limit SCENARIO.ini [--clearance M] [--set k=v]... [--out DIR] [plot options]
int cmd_report_limit(const std::vector<std::string>& args) {
  std::string scenario_path, out_dir;
  std::vector<std::string> overrides;
  double clearance = kLimitClearance;
  PlotOptions options;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (plot_option(args, i, options)) continue;
    if (a == "--out" || a == "--set" || a == "--clearance") {
      if (i + 1 >= args.size()) throw UserError(a + " needs a value");
      const std::string& value = args[++i];
      if (a == "--out") out_dir = value;
      else if (a == "--set") overrides.push_back(value);
      else {
        char* end = nullptr;
        clearance = std::strtod(value.c_str(), &end);
        if (value.empty() || *end != '\0' || !std::isfinite(clearance) || clearance < 0.0)
          throw UserError("--clearance: expected a distance >= 0 m, got '" + value + "'");
      }
    } else if (!a.empty() && a[0] == '-') {
      throw UserError("report limit: unknown option " + a + "\n" + kUsage);
    } else if (scenario_path.empty()) {
      scenario_path = a;
    } else {
      throw UserError("report limit: more than one scenario given: " + scenario_path + " and " + a);
    }
  }
  if (scenario_path.empty()) throw UserError(std::string("report limit needs a scenario file\n") + kUsage);
  const Scenario scenario = load_scenario(scenario_path, overrides);
  const world::TrackModel track = world::build_track(load_track_file(scenario.track_path));
  if (out_dir.empty()) out_dir = "runs/limit_" + std::filesystem::path(scenario_path).stem().string();
  const auto start = std::chrono::steady_clock::now();
  const LimitReport report = limit_report(scenario.vehicle, track, scenario_path, clearance);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::vector<std::string> files = write_limit_report(report, track, out_dir, options);
  std::cout << limit_report_text(report) << "  output      " << files[0] << ", " << files[1] << "\n  figure      "
            << files[2] << "\n"
            << "  speed       " << fixed(wall, 3) << " s\n";
  return 0;
}

int cmd_report(const std::vector<std::string>& args) {
  if (!args.empty() && args[0] == "vehicle") return cmd_report_vehicle({args.begin() + 1, args.end()});
  if (!args.empty() && args[0] == "limit") return cmd_report_limit({args.begin() + 1, args.end()});
  if (args.size() >= 2 && args[0] == "smoothing" && args.size() == 2) {
    std::cout << report_smoothing(args[1]);
    return 0;
  }
  if (args.size() >= 2 && args[0] == "controllers") {
    std::vector<std::string> overrides;
    for (std::size_t i = 2; i < args.size(); ++i) {
      if (args[i] == "--set" && i + 1 < args.size()) overrides.push_back(args[++i]);
      else throw UserError("report controllers: unexpected argument " + args[i] + "\n" + kUsage);
    }
    std::cout << report_controllers(args[1], overrides);
    return 0;
  }
  throw UserError(std::string("report needs 'controllers SCENARIO', 'smoothing TRACK', 'vehicle [CAR]' or 'limit SCENARIO'\n") + kUsage);
}

// a command's folder and plot options (args from `first` on); `what` names
// the command and the folder in messages
std::string folder_and_plot_options(const std::vector<std::string>& args, std::size_t first, const std::string& what,
                                    PlotOptions& options) {
  std::string dir;
  for (std::size_t i = first; i < args.size(); ++i) {
    if (plot_option(args, i, options)) continue;
    if (!args[i].empty() && args[i][0] == '-') throw UserError("unknown option " + args[i] + "\n" + kUsage);
    if (!dir.empty()) throw UserError(what + ": more than one folder given: " + dir + " and " + args[i]);
    dir = args[i];
  }
  if (dir.empty()) throw UserError(what + " needs a folder\n" + kUsage);
  return dir;
}

int cmd_plot(const std::vector<std::string>& args) {
  PlotOptions options;
  const std::string dir = folder_and_plot_options(args, 0, "plot", options);
  for (const auto& f : plot_run(dir, options)) std::cout << f << "\n";
  return 0;
}

// "i/n" with 0 <= i < n
std::pair<int, int> shard_of(const std::string& v) {
  const auto slash = v.find('/');
  if (slash != std::string::npos) {
    char* e1 = nullptr;
    char* e2 = nullptr;
    const std::string a = v.substr(0, slash), b = v.substr(slash + 1);
    const long i = std::strtol(a.c_str(), &e1, 10), n = std::strtol(b.c_str(), &e2, 10);
    if (!a.empty() && !b.empty() && *e1 == '\0' && *e2 == '\0' && n >= 1 && n <= 100000 && i >= 0 && i < n) {
      return {static_cast<int>(i), static_cast<int>(n)};
    }
  }
  throw UserError("--shard " + v + ": expected i/n with 0 <= i < n (e.g. 3/10)");
}

int cmd_sweep(const std::vector<std::string>& args) {
  if (!args.empty() && args[0] == "collect") {
    if (args.size() != 2) throw UserError(std::string("sweep collect needs one sweep folder\n") + kUsage);
    return collect_sweep(args[1]);
  }
  if (!args.empty() && args[0] == "report") {
    std::string dir;
    int top = 10;
    for (std::size_t i = 1; i < args.size(); ++i) {
      if (args[i] == "--top" && i + 1 < args.size()) top = option_int("--top", args[++i], 1, 1000000);
      else if (!args[i].empty() && args[i][0] == '-') throw UserError("sweep report: unknown option " + args[i] + "\n" + kUsage);
      else if (dir.empty()) dir = args[i];
      else throw UserError("sweep report: more than one folder given: " + dir + " and " + args[i]);
    }
    if (dir.empty()) throw UserError(std::string("sweep report needs a sweep folder\n") + kUsage);
    std::cout << sweep_report(sweep_table(dir), top);
    return 0;
  }
  if (!args.empty() && args[0] == "plot") {
    PlotOptions options;
    const std::string dir = folder_and_plot_options(args, 1, "sweep plot", options);
    for (const auto& f : plot_sweep(dir, options)) std::cout << f << "\n";
    return 0;
  }
  std::string path;
  SweepOptions o;
  SlurmOptions slurm;
  PlotOptions plot_options;
  bool use_slurm = false, slurm_option = false, plots = false;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&](const char* flag) -> std::string {
      if (i + 1 >= args.size()) throw UserError(std::string(flag) + " needs a value");
      return args[++i];
    };
    if (plot_option(args, i, plot_options)) continue;
    if (a == "--jobs") o.jobs = option_int("--jobs", value("--jobs"), 1, 4096);
    else if (a == "--out") o.out_dir = value("--out");
    else if (a == "--resume") o.resume = true;
    else if (a == "--plots") plots = true;
    else if (a == "--shard") std::tie(o.shard, o.shards) = shard_of(value("--shard"));
    else if (a == "--slurm") use_slurm = true;
    else if (a == "--partition" || a == "--time" || a == "--array-limit" || a == "--tasks" || a == "--cpus-per-task" ||
             a == "--sbatch-arg" || a == "--dry-run" || a == "--wait") {
      slurm_option = true;
      if (a == "--partition") slurm.partition = value("--partition");
      else if (a == "--time") slurm.time = value("--time");
      else if (a == "--array-limit") slurm.array_limit = option_int(a, value("--array-limit"), 1, 100000);
      else if (a == "--tasks") slurm.tasks = option_int(a, value("--tasks"), 1, 100000);
      else if (a == "--cpus-per-task") slurm.cpus_per_task = option_int(a, value("--cpus-per-task"), 1, 4096);
      else if (a == "--sbatch-arg") slurm.sbatch_args.push_back(value("--sbatch-arg"));
      else if (a == "--dry-run") slurm.dry_run = true;
      else slurm.wait = true;
    }
    else if (!a.empty() && a[0] == '-') throw UserError("sweep: unknown option " + a + "\n" + kUsage);
    else if (path.empty()) path = a;
    else throw UserError("sweep: more than one sweep file given: " + path + " and " + a);
  }
  if (path.empty()) throw UserError(std::string("sweep needs a sweep file\n") + kUsage);
  if (slurm_option && !use_slurm) throw UserError("sweep: --partition, --time, --array-limit, --tasks, --cpus-per-task, --sbatch-arg, --dry-run and --wait go with --slurm");
  if (use_slurm && o.shards > 0) throw UserError("sweep: --slurm and --shard do not go together (each Slurm task runs a shard)");
  if (use_slurm && slurm.dry_run && slurm.wait) throw UserError("sweep: --dry-run and --wait do not go together");
  if (use_slurm) o.slurm = slurm;
  if (plots && (use_slurm || o.shards > 0)) throw UserError("sweep: --plots draws a whole sweep: use paddock sweep plot DIR after collect");
  const int code = run_sweep(path, o);
  if (plots && code != 130) {
    const std::string dir = o.out_dir.empty() ? "runs/" + std::filesystem::path(path).stem().string() : o.out_dir;
    for (const auto& f : plot_sweep(dir, plot_options)) std::cout << "  figure      " << f << "\n";
  }
  return code;
}

int cmd_tune(const std::vector<std::string>& args) {
  std::string path;
  TuneOptions o;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&](const char* flag) -> std::string {
      if (i + 1 >= args.size()) throw UserError(std::string(flag) + " needs a value");
      return args[++i];
    };
    if (a == "--jobs") o.jobs = option_int("--jobs", value("--jobs"), 1, 4096);
    else if (a == "--out") o.out_dir = value("--out");
    else if (a == "--max-evals") o.max_evals = option_int("--max-evals", value("--max-evals"), 1, 100000);
    else if (!a.empty() && a[0] == '-') throw UserError("tune: unknown option " + a + "\n" + kUsage);
    else if (path.empty()) path = a;
    else throw UserError("tune: more than one tune file given: " + path + " and " + a);
  }
  if (path.empty()) throw UserError(std::string("tune needs a tune file\n") + kUsage);
  run_tune(path, o);
  return 0;
}

// replay LOG.mcap [--set k=v]... [--from S] [--until S]
int cmd_replay(const std::vector<std::string>& args) {
  std::string log_path;
  ReplayOptions o;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&](const char* flag) -> std::string {
      if (i + 1 >= args.size()) throw UserError(std::string(flag) + " needs a value");
      return args[++i];
    };
    auto seconds = [&](const char* flag) {
      const std::string v = value(flag);
      char* end = nullptr;
      const double x = std::strtod(v.c_str(), &end);
      if (end == v.c_str() || *end != '\0' || !std::isfinite(x) || x < 0.0)
        throw UserError(std::string(flag) + " " + v + ": expected a time in seconds >= 0");
      return x;
    };
    if (a == "--set") o.overrides.push_back(value("--set"));
    else if (a.rfind("--set=", 0) == 0) o.overrides.push_back(a.substr(6));
    else if (a == "--from") o.from = seconds("--from");
    else if (a == "--until") o.until = seconds("--until");
    else if (a == "--profile") o.profile = true;
    else if (a == "--threads") o.threads = option_int("--threads", value("--threads"), 1, Workers::kMaxThreads);
    else if (!a.empty() && a[0] == '-') throw UserError("unknown option " + a + "\n" + kUsage);
    else if (log_path.empty()) log_path = a;
    else throw UserError("more than one log given: " + log_path + " and " + a);
  }
  if (log_path.empty()) throw UserError(std::string("replay needs a log (run.mcap)\n") + kUsage);
  if (o.from && o.until && *o.until < *o.from) throw UserError("--until must not be before --from");
  const ReplayResult r = replay(log_path, o);
  std::cout << replay_text(log_path, r);
  return 0;
}

volatile std::sig_atomic_t g_stop = 0;
extern "C" void on_stop_signal(int) { g_stop = 1; }

// car SCENARIO.ini [--set k=v]... [--log] [--out DIR]
int cmd_car(const std::vector<std::string>& args) {
  std::string path, out_dir;
  std::vector<std::string> overrides;
  bool log = false;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--log") {
      log = true;
    } else if (a == "--out") {
      if (i + 1 >= args.size()) throw UserError("--out needs a value");
      out_dir = args[++i];
    } else if (a == "--set") {
      if (i + 1 >= args.size()) throw UserError("--set needs a value");
      overrides.push_back(args[++i]);
    } else if (a.rfind("--set=", 0) == 0) {
      overrides.push_back(a.substr(6));
    } else if (!a.empty() && a[0] == '-') {
      throw UserError("car: unknown option " + a + "\n" + kUsage);
    } else if (path.empty()) {
      path = a;
    } else {
      throw UserError("car: more than one scenario given: " + path + " and " + a);
    }
  }
  if (path.empty()) throw UserError(std::string("car needs a scenario (the stack's parameters, [hal] and [car])\n") + kUsage);
  const Scenario scenario = load_scenario(path, overrides);
  if (!scenario.dbc)
    throw UserError(scenario.source + ": the car binary reads the car's CAN bus: [hal] dbc must name its DBC file (include = sensors/ouster.ini)");
  const bool lidar = scenario.autonomy.perception != stack::PerceptionMode::GroundTruth;
  if (lidar && !scenario.lidar_info)
    throw UserError(scenario.source + ": the car binary decodes the LiDAR's packets: [hal] lidar_metadata must name its metadata file (include = sensors/ouster.ini)");
  // the track gives the mission the car's grid position (the origin of its map)
  const world::TrackModel track = world::build_track(load_track_file(scenario.track_path));
  const SimModel model = compile_model(scenario, track);
  car::CarSetup setup;
  setup.stack = model.stack;
  setup.mission = model.mission;
  if (lidar) setup.lidar = scenario.lidar_info;
  setup.layout = scenario.lidar;
  setup.dbc = scenario.dbc.get();
  setup.dbc_source = scenario.hal.dbc;
  setup.car = scenario.car;
  setup.control_period = model.dt_ns * model.every.control;
  setup.camera_width = scenario.camera.width;
  setup.camera_height = scenario.camera.height;
  if (log) {
    if (out_dir.empty()) out_dir = "runs/car_" + scenario.name;
    std::filesystem::create_directories(out_dir);
    setup.log_path = out_dir + "/run.mcap";
    setup.log_files = log_attachments(scenario);
    setup.log_metadata = {{"scenario", scenario.source},
                          {"binary", "paddock car"},
                          {"clock", scenario.car.clock == car::Clock::Lockstep ? "lockstep" : "wall"}};
    setup.log_pose_period = kNsPerSecond / scenario.sim.log_rate;
  }
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  try {
    car::run_car(setup, std::cout, &g_stop);
  } catch (const std::runtime_error& e) {
    throw UserError(std::string("car: ") + e.what());
  }
  return 0;
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
    if (args[0] == "replay") return cmd_replay(rest);
    if (args[0] == "car") return cmd_car(rest);
    if (args[0] == "plot") return cmd_plot(rest);
    if (args[0] == "sweep") return cmd_sweep(rest);
    if (args[0] == "tune") return cmd_tune(rest);
    if (args[0] == "report") return cmd_report(rest);
    if (args[0] == "bench-compare") {
      if (rest.size() != 2) throw UserError("bench-compare needs OLD.json NEW.json\n" + std::string(kUsage));
      const BenchComparison c = compare_benchmarks(read_bench_json(rest[0]), read_bench_json(rest[1]));
      std::cout << bench_comparison_text(c);
      return c.slower > 0 ? 1 : 0;
    }
    if (args[0] == "keys") {
      if (!rest.empty()) throw UserError("keys takes no arguments\n" + std::string(kUsage));
      std::cout << keys_markdown();
      return 0;
    }
    throw UserError("unknown command '" + args[0] + "'\n" + kUsage);
  } catch (const std::exception& e) {
    // user errors (and track errors) carry their file:line already
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
}

}  // namespace paddock::runner
