#pragma once
// What a finished sweep says, from its results.csv alone: the configurations
// (one value per varied key) ranked over every scenario and seed they ran
// on, as a Markdown table with the best one's lines to paste into a
// scenario (`paddock sweep report DIR`), and the sweep's figures
// (`paddock sweep ... --plots`, `paddock sweep plot DIR`).
//
// A configuration's figures: runs, finished runs, mean and worst total time
// (penalties included), cones down or out (sum), mean tracking RMS. It
// ranks by: every run finished first, then the mean total time, then the
// point order. A configuration that won on one track and lost on three is
// no winner here: its mean is over all of them.
#include <string>
#include <vector>

#include "sim/runner/plots.h"

namespace paddock::runner {

struct SweepConfig {
  std::vector<std::string> values;  // per varied key
  int runs = 0, finished = 0;
  double mean_total = 0.0, worst_total = 0.0;  // s, over the finished runs
  int cones = 0;                               // DOO over all runs
  double mean_rms = 0.0;                       // m, over the finished runs
  int first_point = 0;
};

struct SweepTable {
  std::vector<std::string> keys;  // the varied keys (section.key)
  std::vector<SweepConfig> configs;  // ranked, best first
};

// reads DIR/results.csv; throws UserError "file:line: ..." on a malformed one
SweepTable sweep_table(const std::string& dir);

// the top `n` configurations as Markdown, and the best one's lines
std::string sweep_report(const SweepTable& table, int n);

// draws DIR/plots/total_time_<key>.png per numeric varied key (every run's
// total time against the key, coloured by penalties), DIR/plots/heatmap.png
// (the first two numeric keys, the configurations' mean total time) and
// DIR/plots/pareto.png (mean total time against mean tracking RMS per
// configuration, the Pareto front and the best marked); returns the paths
std::vector<std::string> plot_sweep(const std::string& dir, const PlotOptions& options);

}  // namespace paddock::runner
