// the run-summary reader of paddock plot (sim/runner/summary_reader.h): any
// text; a summary it takes has as many of each lap field as laps, finite
// times and counts from 0
#include <cmath>
#include <string>

#include "fuzz/fuzz_target.h"
#include "sim/runner/files.h"
#include "sim/runner/summary_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const paddock::runner::SummaryLaps s = paddock::runner::parse_summary(text, "summary.json");
    const std::size_t n = s.start.size();
    if (s.time.size() != n || s.timed.size() != n || s.doo.size() != n || s.oc.size() != n) __builtin_trap();
    for (std::size_t i = 0; i < n; ++i)
      if (!std::isfinite(s.start[i]) || !std::isfinite(s.time[i]) || s.doo[i] < 0 || s.oc[i] < 0) __builtin_trap();
    if (!std::isfinite(s.total_time)) __builtin_trap();
  } catch (const paddock::runner::UserError&) {
  }
  return 0;
}
