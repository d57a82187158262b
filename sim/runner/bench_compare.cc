#include "sim/runner/bench_compare.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "sim/runner/files.h"

namespace paddock::runner {

namespace {

double to_ns(double value, const std::string& unit) {
  if (unit == "ns") return value;
  if (unit == "us") return value * 1e3;
  if (unit == "ms") return value * 1e6;
  if (unit == "s") return value * 1e9;
  return std::nan("");
}

std::string time_text(double ns) {
  char buf[32];
  if (ns >= 1e9) std::snprintf(buf, sizeof buf, "%.3f s", ns * 1e-9);
  else if (ns >= 1e6) std::snprintf(buf, sizeof buf, "%.3f ms", ns * 1e-6);
  else if (ns >= 1e3) std::snprintf(buf, sizeof buf, "%.3f us", ns * 1e-3);
  else std::snprintf(buf, sizeof buf, "%.1f ns", ns);
  return buf;
}

}  // namespace

std::vector<BenchTiming> read_bench_json(const std::string& path) {
  const std::string text = read_file(path);
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    // the byte offset as a line number
    const std::size_t at = std::min(static_cast<std::size_t>(e.byte), text.size());
    const long line = 1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n');
    throw UserError(path + ":" + std::to_string(line) + ": not JSON (" + e.what() + ")");
  }
  if (!j.is_object() || !j.contains("benchmarks") || !j["benchmarks"].is_array()) {
    throw UserError(path + ": expected Google Benchmark's JSON, an object with a \"benchmarks\" array "
                    "(paddock bench --json FILE)");
  }
  // per benchmark name: its plain run, or its median / mean aggregate
  std::map<std::string, BenchTiming> plain, median, mean;
  std::vector<std::string> order;
  for (const nlohmann::json& b : j["benchmarks"]) {
    const auto field = [&](const char* key) -> const nlohmann::json& {
      if (!b.is_object() || !b.contains(key)) {
        throw UserError(path + ": a benchmark entry without \"" + key + "\"");
      }
      return b[key];
    };
    if (!field("name").is_string() || !field("cpu_time").is_number()) {
      throw UserError(path + ": a benchmark entry whose name is not a string or whose cpu_time is not a number");
    }
    const std::string unit = b.value("time_unit", "ns");
    BenchTiming t;
    t.cpu_ns = to_ns(field("cpu_time").get<double>(), unit);
    if (!std::isfinite(t.cpu_ns)) {
      throw UserError(path + ": benchmark " + field("name").get<std::string>() + " has time unit '" + unit +
                      "' (expected ns, us, ms or s)");
    }
    const std::string run_name = b.value("run_name", field("name").get<std::string>());
    t.name = run_name;
    if (std::find(order.begin(), order.end(), run_name) == order.end()) order.push_back(run_name);
    if (b.value("run_type", "iteration") == "aggregate") {
      const std::string agg = b.value("aggregate_name", "");
      if (agg == "median") median[run_name] = t;
      if (agg == "mean") mean[run_name] = t;
    } else if (!plain.count(run_name)) {
      plain[run_name] = t;
    }
  }
  std::vector<BenchTiming> out;
  for (const std::string& name : order) {
    if (median.count(name)) out.push_back(median[name]);
    else if (mean.count(name)) out.push_back(mean[name]);
    else if (plain.count(name)) out.push_back(plain[name]);
  }
  return out;
}

BenchComparison compare_benchmarks(const std::vector<BenchTiming>& old_runs, const std::vector<BenchTiming>& new_runs,
                                   double threshold) {
  BenchComparison c;
  std::map<std::string, const BenchTiming*> old_by_name;
  for (const BenchTiming& t : old_runs) old_by_name[t.name] = &t;
  std::set<std::string> matched;
  for (const BenchTiming& t : new_runs) {
    const auto it = old_by_name.find(t.name);
    if (it == old_by_name.end()) {
      c.only_new.push_back(t.name);
      continue;
    }
    matched.insert(t.name);
    BenchRow r;
    r.name = t.name;
    r.old_ns = it->second->cpu_ns;
    r.new_ns = t.cpu_ns;
    r.ratio = r.old_ns > 0.0 ? r.new_ns / r.old_ns : std::nan("");
    r.slower = !(r.ratio <= 1.0 + threshold);
    c.slower += r.slower;
    c.rows.push_back(r);
  }
  for (const BenchTiming& t : old_runs)
    if (!matched.count(t.name)) c.only_old.push_back(t.name);
  return c;
}

std::string bench_comparison_text(const BenchComparison& c, double threshold) {
  std::size_t width = 9;
  for (const BenchRow& r : c.rows) width = std::max(width, r.name.size());
  std::ostringstream o;
  char line[512];
  std::snprintf(line, sizeof line, "%-*s  %12s  %12s  %7s\n", static_cast<int>(width), "benchmark", "old (cpu)",
                "new (cpu)", "new/old");
  o << line;
  for (const BenchRow& r : c.rows) {
    std::snprintf(line, sizeof line, "%-*s  %12s  %12s  %7.3f%s\n", static_cast<int>(width), r.name.c_str(),
                  time_text(r.old_ns).c_str(), time_text(r.new_ns).c_str(), r.ratio, r.slower ? "  SLOWER" : "");
    o << line;
  }
  for (const std::string& n : c.only_old) o << n << ": only in OLD\n";
  for (const std::string& n : c.only_new) o << n << ": only in NEW\n";
  o << c.slower << " of " << c.rows.size() << " benchmarks more than " << static_cast<int>(std::lround(threshold * 100))
    << " % slower\n";
  return o.str();
}

}  // namespace paddock::runner
