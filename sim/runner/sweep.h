#pragma once
// paddock sweep: one scenario (or several) run over a set of parameter
// values, on every core, into one folder with a results.csv.
//
// A sweep file is INI in the scenarios' dialect:
//
//   ; scenarios/sweeps/stanley_gain.ini
//   [sweep]
//   scenarios = ../fsg_2023_trackdrive.ini, ../fss_2019_trackdrive.ini
//   combine = grid                 ; grid (every combination) or zip (i-th with i-th)
//   seeds = 1..3                   ; each combination with each seed (default: the scenario's)
//   samples = 20                   ; draws of the uniform()/loguniform() keys
//   sampling = lhs                 ; random or lhs (Latin hypercube)
//   sample_seed = 7
//   [vary]
//   control.stanley.k = linspace(1, 4, 4)          ; 1, 2, 3, 4
//   control.lateral = stanley, combined            ; a list, as written
//   planning.reference.profile.ay_max = logspace(4, 16, 3) ; 4, 8, 16 (geometric, ends included)
//   control.longitudinal.kp = uniform(1, 3)        ; drawn, `samples` times
//   control.combined.kappa_ref = loguniform(0.01, 1)
//   event.timeout = 100..102                       ; whole numbers, ends included
//   [autonomy]                     ; any other section: set for every point
//   planner = oracle
//
// Without `scenarios` the sweep file is itself the base scenario (it
// includes one, and its other sections change it). The points: for each
// scenario, for each combination (grid: the listed keys' product, first key
// slowest, times the samples; zip: the listed keys and the samples side by
// side, all of one length), for each seed. A value goes into the scenario as
// if written on its [vary] line, so a bad one is reported there.
//
// A sweep writes DIR/points.csv (its points: index, scenario, values, seed),
// DIR/points/NNNN/{scenario.ini,summary.json} per point (as `paddock run`
// writes them; summary.json last, so a point with one is done),
// DIR/results.csv (one row per point, in point order, from points.csv and the
// summaries: the same whatever the number of jobs or machines) and
// DIR/timing.csv (wall times, which differ from run to run, kept apart).
// --resume reruns only the points without a summary (an interrupted sweep:
// Ctrl-C, a killed job). On Slurm (--slurm) an array job's tasks each run a
// shard (--shard i/n) into the same DIR, and `paddock sweep collect DIR`
// writes the tables.
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "sim/runner/ini.h"
#include "sim/runner/scenario.h"

namespace paddock::runner {

struct SweepAxis {
  enum class Kind { List, Uniform, LogUniform };
  std::string section, key;  // the scenario key it varies
  Kind kind = Kind::List;
  std::vector<std::string> values;  // List: the values, as written or computed
  double lo = 0.0, hi = 0.0;        // Uniform, LogUniform: the interval drawn from
  IniEntry where;                   // its [vary] line
  std::string name() const { return section + "." + key; }
};

struct SweepSpec {
  std::string path;                    // the sweep file
  std::string name;                    // its stem
  std::vector<std::string> scenarios;  // the base scenarios' paths; empty: the sweep file itself
  std::vector<IniEntry> common;        // the sweep file's entries outside [sweep] and [vary]
  std::vector<SweepAxis> axes;         // in the file's order
  bool zip = false;
  bool latin_hypercube = false;
  int samples = 0;
  std::uint64_t sample_seed = 1;
  std::vector<std::uint64_t> seeds;  // empty: each scenario's own seed
  IniEntry seeds_where;
};

// reads and checks a sweep file; throws UserError "file:line: ..." on a bad one
SweepSpec load_sweep(const std::string& path);

struct SweepPoint {
  int index = 0;
  std::size_t scenario = 0;         // into SweepSpec::scenarios (0 when the file is the base)
  std::vector<std::string> values;  // per axis, as the scenario gets it
  std::optional<std::uint64_t> seed;
};

// every point, in order (see the top); throws UserError when the axes do not fit
std::vector<SweepPoint> expand_sweep(const SweepSpec& spec);

// the point's scenario, checked; throws UserError "sweep.ini:line: ..." for a
// value the scenario refuses
Scenario sweep_point_scenario(const SweepSpec& spec, const SweepPoint& point);

struct SlurmOptions {
  std::string partition;       // --partition (empty: the cluster's default)
  std::string time;            // --time limit per task (empty: the partition's)
  int array_limit = 0;         // at most this many tasks at once (0: no limit)
  int tasks = 0;               // array tasks (0: one per point, at most 100)
  int cpus_per_task = 1;       // cores per task (its --jobs)
  std::vector<std::string> sbatch_args;  // more sbatch options, verbatim
  bool dry_run = false;        // write the script, do not submit
  bool wait = false;           // wait for the job, then collect
};

struct SweepOptions {
  std::string out_dir;  // empty: runs/<sweep name>
  int jobs = 0;         // 0: every core
  bool resume = false;
  int shard = -1, shards = 0;        // --shard i/n: only the i-th of n equal slices of the points
  std::optional<SlurmOptions> slurm;  // --slurm: submit to Slurm instead of running here
};

// runs the sweep (or its shard, or submits it to Slurm) and prints where its
// results are; returns the exit code: 0 every point ran (a DNF is a result),
// 1 some point failed to run (its error is in the table), 130 interrupted
// (--resume finishes it)
int run_sweep(const std::string& path, const SweepOptions& options);

// paddock sweep collect DIR: results.csv and timing.csv from DIR/points.csv
// and the points' summaries; 0 when every point has one, else 1 (the
// missing ones are named)
int collect_sweep(const std::string& dir);

// DIR/results.csv's text: DIR/points.csv's rows (the point, its scenario, the
// varied values, the seed) with the figures of each point's summary (a point
// without one: its error, or "not run")
std::string sweep_results_csv(const std::string& dir);

// the folder of point i of n within a sweep's folder
std::string sweep_point_dir(const std::string& dir, int index, std::size_t count);

// the points of shard i of n: [i P / n, (i + 1) P / n)
std::pair<std::size_t, std::size_t> sweep_shard(std::size_t points, int i, int n);

// shared by sweep and tune files:
// the whole text as a finite number, or none
std::optional<double> finite_number(const std::string& s);
// "a, b, c" -> its trimmed items
std::vector<std::string> split_list(const std::string& s);
// `e`'s value as seeds: a list (1, 4, 9) or a range (1..5); throws UserError
std::vector<std::uint64_t> seed_list(const IniEntry& e);
// `e`'s value as scenario files, relative to the file it is written in
std::vector<std::string> scenario_list(const IniEntry& e);
// a CSV cell: quoted when it holds a comma, a quote or a line break
std::string csv_cell(const std::string& s);
// one CSV line's cells (quotes as csv_cell writes them)
std::vector<std::string> csv_split(const std::string& line);

}  // namespace paddock::runner
