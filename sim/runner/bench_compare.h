#pragma once
// paddock bench compare OLD.json NEW.json: two runs of the benchmarks (Google
// Benchmark's JSON, `paddock bench --json FILE`) side by side, one line per
// benchmark both ran: its time in each and the ratio NEW / OLD, flagged when
// NEW is more than `threshold` slower. Timing is noisy on shared machines:
// compare two runs made one after the other on the same machine.
#include <string>
#include <vector>

namespace paddock::runner {

struct BenchTiming {
  std::string name;
  double cpu_ns = 0.0;  // CPU time per iteration, in nanoseconds
};

struct BenchRow {
  std::string name;
  double old_ns = 0.0, new_ns = 0.0;  // CPU time per iteration
  double ratio = 0.0;                 // new / old
  bool slower = false;                // ratio > 1 + threshold
};

struct BenchComparison {
  std::vector<BenchRow> rows;              // in NEW's order
  std::vector<std::string> only_old, only_new;
  int slower = 0;
};

// the benchmarks of one JSON file (aggregates such as _mean, when repeated,
// are used in place of their runs: the median when there is one); throws
// UserError naming the file (and the line, for malformed JSON) and what was
// expected
std::vector<BenchTiming> read_bench_json(const std::string& path);

BenchComparison compare_benchmarks(const std::vector<BenchTiming>& old_runs, const std::vector<BenchTiming>& new_runs,
                                   double threshold = 0.10);

// the table and a last line with the count of slower ones
std::string bench_comparison_text(const BenchComparison& c, double threshold = 0.10);

}  // namespace paddock::runner
