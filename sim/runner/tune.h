#pragma once
// paddock tune: a derivative-free optimiser (NLopt) over chosen scenario keys
// within bounds, whose objective is a weighted total over closed-loop runs
// of several scenarios.
//
// A tune file is INI in the scenarios' dialect:
//
//   ; scenarios/tunes/longitudinal.ini
//   [tune]
//   scenarios = ../fsg_2023_autocross.ini, ../fss_2019_autocross.ini
//   weights = 1, 1          ; per scenario (default: 1 each)
//   seeds = 1..2            ; each scenario with each seed, averaged (default: its own)
//   algorithm = sbplx       ; sbplx, bobyqa, neldermead, cobyla, crs2 (global)
//   max_evals = 60          ; evaluations of the objective at most
//   rel_tol = 1e-4          ; stop when a step moves the objective by less (relative)
//   initial_step = 0.2      ; first step, as a share of each key's range
//   nlopt_seed = 1          ; NLopt's own random numbers (crs2)
//   tracking_weight = 10    ; s per m of RMS lateral error
//   cone_weight = 2         ; s per cone down or out (on top of the event's 2 s)
//   dnf_cost = 1000         ; s for a run that does not finish
//   [optimise]
//   control.longitudinal.kp = bounds(0.1, 10)      ; searched linearly
//   control.combined.kappa_ref = logbounds(0.01, 1) ; searched in log
//   [control.longitudinal]  ; any other section: set for every run; a key
//   kp = 0.5                ; being optimised starts from the value it has here
//
// Each run's cost: its total time (raw time and the event's penalties)
// + tracking_weight x its RMS lateral error + cone_weight x its cones down
// or out, or dnf_cost when it does not finish; the objective is the
// weighted mean over the scenarios (and seeds). The runs of one evaluation
// run in parallel. A tune writes DIR/evaluations.csv (one row per
// evaluation: the keys' values, the objective, each run's cost) and
// DIR/best.ini (the best values in their sections, to include in a
// scenario after its other includes).
#include <cstdint>
#include <string>
#include <vector>

#include "sim/runner/ini.h"

namespace paddock::runner {

struct TuneKey {
  std::string section, key;
  double lo = 0.0, hi = 0.0;
  bool log = false;  // searched in log(value)
  IniEntry where;    // its [optimise] line
  std::string name() const { return section + "." + key; }
};

struct TuneSpec {
  std::string path, name;
  std::vector<std::string> scenarios;  // paths
  std::vector<double> weights;         // one per scenario
  std::vector<std::uint64_t> seeds;    // empty: each scenario's own
  IniEntry seeds_where;
  std::vector<IniEntry> common;  // the tune file's entries outside [tune] and [optimise]
  std::vector<TuneKey> keys;
  std::string algorithm = "sbplx";
  int max_evals = 60;
  double rel_tol = 1e-4;
  double initial_step = 0.2;
  std::uint64_t nlopt_seed = 1;
  double tracking_weight = 10.0, cone_weight = 2.0, dnf_cost = 1000.0;
};

// reads and checks a tune file; throws UserError "file:line: ..." on a bad one
TuneSpec load_tune(const std::string& path);

struct TuneOptions {
  std::string out_dir;  // empty: runs/<tune name>
  int jobs = 0;         // runs at once (0: every core)
  int max_evals = 0;    // overrides the file's (0: the file's)
};

struct TuneResult {
  std::vector<double> start, best;  // the keys' values
  double start_objective = 0.0, best_objective = 0.0;
  int evaluations = 0;
  std::string stop_reason;
};

// runs the optimisation, writes DIR/evaluations.csv and DIR/best.ini, and
// prints its progress (stderr) and result (stdout)
TuneResult run_tune(const std::string& path, const TuneOptions& options);

}  // namespace paddock::runner
