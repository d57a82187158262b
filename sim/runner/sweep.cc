#include "sim/runner/sweep.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <thread>

#include "autonomy/common/format.h"
#include "sim/runner/files.h"
#include "sim/runner/report.h"
#include "sim/runner/simulation.h"

namespace paddock::runner {
namespace {

namespace fs = std::filesystem;

}  // namespace

std::vector<std::string> split_list(const std::string& s) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (true) {
    const auto comma = s.find(',', start);
    out.push_back(trim(s.substr(start, comma == std::string::npos ? std::string::npos : comma - start)));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

std::optional<double> finite_number(const std::string& s) {
  if (s.empty()) return std::nullopt;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (*end != '\0' || !std::isfinite(v)) return std::nullopt;
  return v;
}

namespace {

std::optional<std::int64_t> whole(const std::string& s) {
  if (s.empty()) return std::nullopt;
  char* end = nullptr;
  const long long v = std::strtoll(s.c_str(), &end, 10);
  if (*end != '\0') return std::nullopt;
  return static_cast<std::int64_t>(v);
}

// "name(a, b[, c])" -> its arguments; nullopt when `s` is no call of `name`
std::optional<std::vector<std::string>> call_args(const std::string& s, const std::string& name) {
  if (s.rfind(name + "(", 0) != 0 || s.back() != ')') return std::nullopt;
  return split_list(s.substr(name.size() + 1, s.size() - name.size() - 2));
}

// "a..b", whole numbers, a <= b: nullopt when `s` is not of that form
std::optional<std::pair<std::int64_t, std::int64_t>> int_range(const std::string& s) {
  const auto dots = s.find("..");
  if (dots == std::string::npos) return std::nullopt;
  const auto a = whole(trim(s.substr(0, dots))), b = whole(trim(s.substr(dots + 2)));
  if (!a || !b) return std::nullopt;
  return std::make_pair(*a, *b);
}

constexpr std::int64_t kMaxValues = 100000;

// the numbers of `args` (named in messages by `e` and `what`)
std::vector<double> numbers_of(const IniEntry& e, const std::vector<std::string>& args, const std::string& what,
                               std::size_t count) {
  if (args.size() != count) {
    throw UserError(e.where() + ": " + what + " takes " + std::to_string(count) + " numbers, got '" + e.value + "'");
  }
  std::vector<double> out;
  for (const std::string& a : args) {
    const auto v = finite_number(a);
    if (!v) throw UserError(e.where() + ": " + what + ": '" + a + "' is not a finite number");
    out.push_back(*v);
  }
  return out;
}

int count_of(const IniEntry& e, double n, const std::string& what) {
  if (!(n >= 1.0 && n <= static_cast<double>(kMaxValues) && n == std::floor(n))) {
    throw UserError(e.where() + ": " + what + ": the count must be a whole number from 1 to " + std::to_string(kMaxValues));
  }
  return static_cast<int>(n);
}

SweepAxis parse_axis(const IniEntry& e) {
  SweepAxis a;
  a.where = e;
  const auto dot = e.key.rfind('.');
  if (dot == std::string::npos || dot == 0 || dot + 1 == e.key.size()) {
    throw UserError(e.where() + ": [vary] " + e.key + ": expected section.key (e.g. control.stanley.k)");
  }
  a.section = e.key.substr(0, dot);
  a.key = e.key.substr(dot + 1);
  const std::string& v = e.value;
  if (v.empty()) throw UserError(e.where() + ": [vary] " + e.key + " has no values");
  if (const auto ls = call_args(v, "linspace")) {
    const auto x = numbers_of(e, *ls, "linspace(first, last, count)", 3);
    const int n = count_of(e, x[2], "linspace");
    for (int i = 0; i < n; ++i) {
      // the ends exact
      const double t = n == 1 ? 0.0 : static_cast<double>(i) / (n - 1);
      a.values.push_back(fmt(i == n - 1 ? x[1] : x[0] + (x[1] - x[0]) * t));
    }
  } else if (const auto lg = call_args(v, "logspace")) {
    const auto x = numbers_of(e, *lg, "logspace(first, last, count)", 3);
    if (!(x[0] > 0.0 && x[1] > 0.0)) throw UserError(e.where() + ": logspace(first, last, count): first and last must be > 0");
    const int n = count_of(e, x[2], "logspace");
    for (int i = 0; i < n; ++i) {
      const double t = n == 1 ? 0.0 : static_cast<double>(i) / (n - 1);
      a.values.push_back(fmt(i == 0 ? x[0] : i == n - 1 ? x[1] : x[0] * std::pow(x[1] / x[0], t)));
    }
  } else if (const auto un = call_args(v, "uniform")) {
    const auto x = numbers_of(e, *un, "uniform(low, high)", 2);
    if (!(x[0] < x[1])) throw UserError(e.where() + ": uniform(low, high): low must be below high");
    a.kind = SweepAxis::Kind::Uniform;
    a.lo = x[0];
    a.hi = x[1];
  } else if (const auto lu = call_args(v, "loguniform")) {
    const auto x = numbers_of(e, *lu, "loguniform(low, high)", 2);
    if (!(x[0] > 0.0 && x[0] < x[1])) throw UserError(e.where() + ": loguniform(low, high): expected 0 < low < high");
    a.kind = SweepAxis::Kind::LogUniform;
    a.lo = x[0];
    a.hi = x[1];
  } else if (const auto r = int_range(v)) {
    if (r->second < r->first || r->second - r->first >= kMaxValues) {
      throw UserError(e.where() + ": " + v + ": expected first..last with first <= last, at most " +
                      std::to_string(kMaxValues) + " values");
    }
    for (std::int64_t i = r->first; i <= r->second; ++i) a.values.push_back(std::to_string(i));
  } else {
    a.values = split_list(v);
    for (const std::string& x : a.values) {
      if (x.empty()) throw UserError(e.where() + ": [vary] " + e.key + ": an empty value in '" + v + "'");
    }
  }
  return a;
}

}  // namespace

std::vector<std::uint64_t> seed_list(const IniEntry& e) {
  std::vector<std::uint64_t> out;
  const std::string expected = ": seeds: expected whole numbers >= 0, as a list (1, 4, 9) or a range (1..5)";
  if (const auto r = int_range(e.value)) {
    if (r->first < 0 || r->second < r->first || r->second - r->first >= kMaxValues) throw UserError(e.where() + expected);
    for (std::int64_t i = r->first; i <= r->second; ++i) out.push_back(static_cast<std::uint64_t>(i));
    return out;
  }
  for (const std::string& x : split_list(e.value)) {
    const auto v = whole(x);
    if (!v || *v < 0) throw UserError(e.where() + expected + ", got '" + x + "'");
    out.push_back(static_cast<std::uint64_t>(*v));
  }
  return out;
}

std::vector<std::string> scenario_list(const IniEntry& e) {
  std::vector<std::string> out;
  for (const std::string& s : split_list(e.value)) {
    if (s.empty()) throw UserError(e.where() + ": scenarios: an empty file name in '" + e.value + "'");
    const fs::path p(s);
    out.push_back((p.is_absolute() ? p : fs::path(e.file).parent_path() / p).lexically_normal().string());
  }
  if (out.empty()) throw UserError(e.where() + ": scenarios: expected one scenario file or more");
  return out;
}

std::string csv_cell(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) {
    if (c == '"') q += '"';
    q += c == '\n' || c == '\r' ? ' ' : c;
  }
  return q + "\"";
}

std::vector<std::string> csv_split(const std::string& line) {
  std::vector<std::string> out(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        out.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        out.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      out.emplace_back();
    } else {
      out.back() += c;
    }
  }
  return out;
}


namespace {

// the figures of a point's summary.json for its results.csv row

const char* const kFigureColumns[] = {
    "finished",       "dnf_reason",        "laps",         "best_lap_s",   "mean_lap_s",
    "raw_time_s",     "total_time_s",      "doo",          "oc",           "uss",
    "penalty_s",      "tracking_rms_m",    "tracking_max_m", "itae",       "ate_rms_m",
    "ate_max_m",      "map_rmse_m",        "map_precision", "map_recall",  "perception_precision",
    "perception_recall", "expectations_failed", "error"};

std::string num(const nlohmann::json& j, const char* key) {
  if (!j.is_object() || !j.contains(key) || !j[key].is_number()) return "";
  return fmt(j[key].get<double>());
}

std::vector<std::string> figures_of(const nlohmann::json& s) {
  std::vector<std::string> c;
  c.push_back(s.value("finished", false) ? "true" : "false");
  c.push_back(s.value("dnf_reason", std::string()));
  const auto& laps = s.contains("laps") ? s["laps"] : nlohmann::json::array();
  double best = INFINITY, sum = 0.0;
  int timed = 0;
  for (const auto& lap : laps) {
    if (!lap.value("timed", false)) continue;
    const double t = lap.value("time", 0.0);
    best = std::min(best, t);
    sum += t;
    ++timed;
  }
  c.push_back(std::to_string(laps.size()));
  c.push_back(timed > 0 ? fmt(best) : "");
  c.push_back(timed > 0 ? fmt(sum / timed) : "");
  c.push_back(num(s, "raw_time"));
  c.push_back(num(s, "total_time"));
  const auto& pen = s.contains("penalties") ? s["penalties"] : nlohmann::json::object();
  c.push_back(num(pen, "doo"));
  c.push_back(num(pen, "oc"));
  c.push_back(num(pen, "uss"));
  c.push_back(num(pen, "seconds"));
  const auto& tr = s.contains("tracking") ? s["tracking"] : nlohmann::json::object();
  c.push_back(num(tr, "rms"));
  c.push_back(num(tr, "max"));
  c.push_back(num(tr, "itae"));
  const auto& sl = s.contains("slam") ? s["slam"] : nlohmann::json::object();
  c.push_back(num(sl, "ate_rms_m"));
  c.push_back(num(sl, "ate_max_m"));
  c.push_back(num(sl, "map_rmse_m"));
  c.push_back(num(sl, "map_precision"));
  c.push_back(num(sl, "map_recall"));
  // the perception's headline: over its range bins
  double det = 0.0, det_matched = 0.0, vis = 0.0, vis_matched = 0.0;
  if (s.contains("perception") && s["perception"].contains("bins")) {
    for (const auto& b : s["perception"]["bins"]) {
      det += b.value("detections", 0.0);
      det_matched += b.value("detections_matched", 0.0);
      vis += b.value("visible", 0.0);
      vis_matched += b.value("visible_matched", 0.0);
    }
  }
  c.push_back(det > 0.0 ? fmt(det_matched / det) : "");
  c.push_back(vis > 0.0 ? fmt(vis_matched / vis) : "");
  c.push_back(std::to_string(s.contains("expectations_failed") ? s["expectations_failed"].size() : 0));
  c.push_back("");
  return c;
}

// SIGINT: the first stops handing out points, the second exits at once
volatile std::sig_atomic_t g_interrupted = 0;
extern "C" void on_interrupt(int) {
  if (g_interrupted) std::_Exit(130);
  g_interrupted = 1;
  static const char msg[] = "\nsweep: interrupted: finishing the points that are running (Ctrl-C again to stop at once)\n";
  const ssize_t w = write(STDERR_FILENO, msg, sizeof msg - 1);  // (async-signal-safe)
  (void)w;
}

std::string minutes_text(double s) {
  if (!std::isfinite(s)) return "-";
  if (s < 90.0) return std::to_string(static_cast<int>(std::lround(s))) + " s";
  if (s < 5400.0) return std::to_string(static_cast<int>(std::lround(s / 60.0))) + " min";
  return fixed(s / 3600.0, 1) + " h";
}

}  // namespace

SweepSpec load_sweep(const std::string& path) {
  SweepSpec spec;
  spec.path = path;
  spec.name = fs::path(path).stem().string();
  const std::vector<IniEntry> entries = read_ini_file(path);
  bool has_sweep = false;
  std::optional<IniEntry> samples, sampling, sample_seed;
  for (const IniEntry& e : entries) {
    if (e.section == "vary") {
      spec.axes.push_back(parse_axis(e));
      continue;
    }
    if (e.section != "sweep") {
      spec.common.push_back(e);
      continue;
    }
    has_sweep = true;
    if (e.key == "scenarios") {
      spec.scenarios = scenario_list(e);
    } else if (e.key == "combine") {
      if (e.value != "grid" && e.value != "zip") throw UserError(e.where() + ": combine: expected grid or zip, got '" + e.value + "'");
      spec.zip = e.value == "zip";
    } else if (e.key == "seeds") {
      spec.seeds = seed_list(e);
      spec.seeds_where = e;
    } else if (e.key == "samples") {
      const auto n = whole(e.value);
      if (!n || *n < 1 || *n > kMaxValues) throw UserError(e.where() + ": samples: expected a whole number from 1 to " + std::to_string(kMaxValues));
      spec.samples = static_cast<int>(*n);
      samples = e;
    } else if (e.key == "sampling") {
      if (e.value != "random" && e.value != "lhs") throw UserError(e.where() + ": sampling: expected random or lhs, got '" + e.value + "'");
      spec.latin_hypercube = e.value == "lhs";
      sampling = e;
    } else if (e.key == "sample_seed") {
      const auto n = whole(e.value);
      if (!n || *n < 0) throw UserError(e.where() + ": sample_seed: expected a whole number >= 0");
      spec.sample_seed = static_cast<std::uint64_t>(*n);
      sample_seed = e;
    } else {
      throw UserError(e.where() + ": [sweep] unknown key '" + e.key +
                      "'; expected scenarios, combine, seeds, samples, sampling or sample_seed");
    }
  }
  if (!has_sweep && spec.axes.empty()) {
    throw UserError(path + ": no [sweep] or [vary] section: a sweep file names its scenarios in [sweep] and its keys in [vary]");
  }
  const bool sampled = std::any_of(spec.axes.begin(), spec.axes.end(), [](const SweepAxis& a) { return a.kind != SweepAxis::Kind::List; });
  if (sampled && spec.samples == 0) {
    throw UserError(path + ": [vary] draws values (uniform/loguniform) but [sweep] samples is not set");
  }
  if (!sampled && samples) throw UserError(samples->where() + ": samples is set but no [vary] key draws values (uniform/loguniform)");
  if (!sampled && sampling) throw UserError(sampling->where() + ": sampling is set but no [vary] key draws values (uniform/loguniform)");
  if (!sampled && sample_seed) throw UserError(sample_seed->where() + ": sample_seed is set but no [vary] key draws values (uniform/loguniform)");
  for (std::size_t i = 0; i < spec.axes.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (spec.axes[i].name() == spec.axes[j].name()) {
        throw UserError(spec.axes[i].where.where() + ": [vary] " + spec.axes[i].name() + " is already varied at line " +
                        std::to_string(spec.axes[j].where.line));
      }
    }
    if (spec.axes[i].name() == "scenario.seed" && !spec.seeds.empty()) {
      throw UserError(spec.axes[i].where.where() + ": scenario.seed is varied and [sweep] seeds is set: use one of them");
    }
  }
  return spec;
}

std::vector<SweepPoint> expand_sweep(const SweepSpec& spec) {
  // the drawn values: samples x (sampled axes), random or Latin hypercube
  std::vector<std::size_t> listed, drawn;
  for (std::size_t i = 0; i < spec.axes.size(); ++i) (spec.axes[i].kind == SweepAxis::Kind::List ? listed : drawn).push_back(i);
  const auto n = static_cast<std::size_t>(spec.samples);
  std::vector<std::vector<std::string>> draws(drawn.empty() ? 0 : n, std::vector<std::string>(drawn.size()));
  if (!drawn.empty()) {
    std::mt19937_64 rng(spec.sample_seed);
    // u in [0, 1) from 53 random bits (the same on every platform, unlike
    // std::uniform_real_distribution)
    const auto u01 = [&rng] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };
    std::vector<std::vector<double>> u(n, std::vector<double>(drawn.size()));
    if (spec.latin_hypercube) {
      // per axis, one draw in each of n equal strata, the strata shuffled
      for (std::size_t a = 0; a < drawn.size(); ++a) {
        std::vector<std::size_t> perm(n);
        for (std::size_t i = 0; i < n; ++i) perm[i] = i;
        for (std::size_t i = n; i > 1; --i) std::swap(perm[i - 1], perm[static_cast<std::size_t>(rng() % i)]);
        for (std::size_t i = 0; i < n; ++i) u[i][a] = (static_cast<double>(perm[i]) + u01()) / static_cast<double>(n);
      }
    } else {
      for (std::size_t i = 0; i < n; ++i)
        for (std::size_t a = 0; a < drawn.size(); ++a) u[i][a] = u01();
    }
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t a = 0; a < drawn.size(); ++a) {
        const SweepAxis& ax = spec.axes[drawn[a]];
        const double x = ax.kind == SweepAxis::Kind::Uniform
                             ? ax.lo + (ax.hi - ax.lo) * u[i][a]
                             : std::exp(std::log(ax.lo) + (std::log(ax.hi) - std::log(ax.lo)) * u[i][a]);
        draws[i][a] = fmt(std::min(std::max(x, ax.lo), ax.hi));
      }
    }
  }

  // the combinations: per axis, the index of its value
  std::vector<std::vector<std::string>> combos;
  const auto combine_with_draws = [&](std::vector<std::string> values) {
    if (drawn.empty()) {
      combos.push_back(values);
      return;
    }
    for (std::size_t i = 0; i < n; ++i) {
      std::vector<std::string> v = values;
      for (std::size_t a = 0; a < drawn.size(); ++a) v[drawn[a]] = draws[i][a];
      combos.push_back(v);
    }
  };
  if (spec.zip) {
    std::size_t len = drawn.empty() ? 0 : n;
    const SweepAxis* first = nullptr;
    for (std::size_t a : listed) {
      const SweepAxis& ax = spec.axes[a];
      if (first == nullptr && drawn.empty()) {
        first = &ax;
        len = ax.values.size();
      } else if (ax.values.size() != len) {
        throw UserError(ax.where.where() + ": combine = zip: " + ax.name() + " has " + std::to_string(ax.values.size()) +
                        " values, but " + (first ? first->name() + " has " : std::string("samples is ")) + std::to_string(len));
      }
    }
    if (spec.axes.empty()) len = 1;
    for (std::size_t i = 0; i < len; ++i) {
      std::vector<std::string> v(spec.axes.size());
      for (std::size_t a : listed) v[a] = spec.axes[a].values[i];
      for (std::size_t a = 0; a < drawn.size(); ++a) v[drawn[a]] = draws[i][a];
      combos.push_back(v);
    }
  } else {
    std::size_t total = 1;
    for (std::size_t a : listed) {
      total *= spec.axes[a].values.size();
      if (total * std::max<std::size_t>(n, 1) > static_cast<std::size_t>(kMaxValues)) {
        throw UserError(spec.path + ": combine = grid gives more than " + std::to_string(kMaxValues) + " combinations");
      }
    }
    std::vector<std::size_t> idx(listed.size(), 0);
    for (std::size_t c = 0; c < total; ++c) {
      std::vector<std::string> v(spec.axes.size());
      for (std::size_t k = 0; k < listed.size(); ++k) v[listed[k]] = spec.axes[listed[k]].values[idx[k]];
      combine_with_draws(v);
      // the last listed key fastest
      for (std::size_t k = listed.size(); k-- > 0;) {
        if (++idx[k] < spec.axes[listed[k]].values.size()) break;
        idx[k] = 0;
      }
    }
  }

  std::vector<SweepPoint> points;
  const std::size_t scenarios = std::max<std::size_t>(spec.scenarios.size(), 1);
  const std::size_t seeds = std::max<std::size_t>(spec.seeds.size(), 1);
  if (scenarios * combos.size() * seeds > static_cast<std::size_t>(kMaxValues)) {
    throw UserError(spec.path + ": the sweep has more than " + std::to_string(kMaxValues) + " points");
  }
  for (std::size_t s = 0; s < scenarios; ++s) {
    for (const auto& v : combos) {
      for (std::size_t k = 0; k < seeds; ++k) {
        SweepPoint p;
        p.index = static_cast<int>(points.size());
        p.scenario = s;
        p.values = v;
        if (!spec.seeds.empty()) p.seed = spec.seeds[k];
        points.push_back(p);
      }
    }
  }
  return points;
}

Scenario sweep_point_scenario(const SweepSpec& spec, const SweepPoint& point) {
  std::vector<IniEntry> entries;
  std::string base;
  if (spec.scenarios.empty()) {
    base = spec.path;
    entries = spec.common;
  } else {
    base = spec.scenarios.at(point.scenario);
    entries = read_ini_file(base);
    entries.insert(entries.end(), spec.common.begin(), spec.common.end());
  }
  for (std::size_t a = 0; a < spec.axes.size(); ++a) {
    IniEntry e = spec.axes[a].where;
    e.section = spec.axes[a].section;
    e.key = spec.axes[a].key;
    e.value = point.values.at(a);
    entries.push_back(e);
  }
  if (point.seed) {
    IniEntry e = spec.seeds_where;
    e.section = "scenario";
    e.key = "seed";
    e.value = std::to_string(*point.seed);
    entries.push_back(e);
  }
  Scenario sc = load_scenario_entries(entries, base);
  if (sc.hal.transport == Transport::Udp)
    throw UserError(base + ": [hal] transport = udp runs one simulation against one car binary; a sweep runs many side by side (use memory or wire)");
  return sc;
}

namespace {

// DIR/points.csv: the points, with the seed each one runs with
std::string manifest_csv(const SweepSpec& spec, const std::vector<SweepPoint>& points, const std::vector<Scenario>& scenarios) {
  std::ostringstream o;
  o << "point,scenario";
  for (const SweepAxis& a : spec.axes) o << "," << csv_cell(a.name());
  o << ",seed\n";
  for (std::size_t i = 0; i < points.size(); ++i) {
    o << points[i].index << "," << csv_cell(scenarios[i].name);
    for (const std::string& v : points[i].values) o << "," << csv_cell(v);
    o << "," << scenarios[i].scenario.seed << "\n";
  }
  return o.str();
}

struct Manifest {
  std::string header;                      // the line as written
  std::vector<std::string> lines;          // one per point, as written
  std::vector<int> index;                  // each line's point
};

Manifest read_manifest(const std::string& dir) {
  const std::string path = (fs::path(dir) / "points.csv").string();
  if (!fs::exists(path)) throw UserError(dir + ": no points.csv here: not a sweep's folder");
  Manifest m;
  std::istringstream in(read_file(path));
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (number == 1) {
      if (line.rfind("point,scenario", 0) != 0) throw UserError(path + ":1: expected the header point,scenario,...");
      m.header = line;
      continue;
    }
    if (line.empty()) continue;
    const auto p = whole(csv_split(line).front());
    if (!p || *p != static_cast<std::int64_t>(m.lines.size())) {
      throw UserError(path + ":" + std::to_string(number) + ": expected point " + std::to_string(m.lines.size()));
    }
    m.lines.push_back(line);
    m.index.push_back(static_cast<int>(*p));
  }
  return m;
}

}  // namespace

std::string sweep_results_csv(const std::string& dir) {
  const Manifest m = read_manifest(dir);
  std::ostringstream o;
  o << m.header;
  for (const char* c : kFigureColumns) o << "," << c;
  o << "\n";
  for (std::size_t i = 0; i < m.lines.size(); ++i) {
    const std::string pd = sweep_point_dir(dir, m.index[i], m.lines.size());
    std::vector<std::string> figures;
    if (fs::exists(pd + "/summary.json")) {
      const nlohmann::json s = nlohmann::json::parse(read_file(pd + "/summary.json"), nullptr, false);
      if (s.is_discarded()) {
        figures.assign(std::size(kFigureColumns), "");
        figures.back() = pd + "/summary.json: not valid JSON";
      } else {
        figures = figures_of(s);
      }
    } else {
      figures.assign(std::size(kFigureColumns), "");
      figures.back() = fs::exists(pd + "/error.txt") ? trim(read_file(pd + "/error.txt")) : "not run";
    }
    o << m.lines[i];
    for (const std::string& f : figures) o << "," << csv_cell(f);
    o << "\n";
  }
  return o.str();
}

int collect_sweep(const std::string& dir) {
  const Manifest m = read_manifest(dir);
  write_file_atomic(dir + "/results.csv", sweep_results_csv(dir));
  std::string timing = "point,wall_time_s\n";
  std::vector<int> missing;
  for (std::size_t i = 0; i < m.lines.size(); ++i) {
    const std::string pd = sweep_point_dir(dir, m.index[i], m.lines.size());
    if (!fs::exists(pd + "/summary.json")) {
      missing.push_back(m.index[i]);
      continue;
    }
    const nlohmann::json s = nlohmann::json::parse(read_file(pd + "/summary.json"), nullptr, false);
    timing += std::to_string(m.index[i]) + "," + (s.is_discarded() ? std::string() : num(s, "wall_time")) + "\n";
  }
  write_file_atomic(dir + "/timing.csv", timing);
  std::cout << "  results     " << dir << "/results.csv (" << m.lines.size() - missing.size() << " of " << m.lines.size()
            << " points done)\n";
  if (!missing.empty()) {
    std::string list;
    for (std::size_t k = 0; k < missing.size() && k < 20; ++k) list += (k ? ", " : "") + std::to_string(missing[k]);
    if (missing.size() > 20) list += ", ...";
    std::cout << "  missing     " << missing.size() << " points without a summary: " << list
              << " (their error, if any, is in results.csv)\n";
  }
  return missing.empty() ? 0 : 1;
}

std::string sweep_point_dir(const std::string& dir, int index, std::size_t count) {
  const int width = std::max<int>(4, static_cast<int>(std::to_string(count > 0 ? count - 1 : 0).size()));
  char buf[32];
  std::snprintf(buf, sizeof buf, "%0*d", width, index);
  return (fs::path(dir) / "points" / buf).string();
}

std::pair<std::size_t, std::size_t> sweep_shard(std::size_t points, int i, int n) {
  const auto a = static_cast<std::size_t>(i) * points / static_cast<std::size_t>(n);
  const auto b = static_cast<std::size_t>(i + 1) * points / static_cast<std::size_t>(n);
  return {a, b};
}

namespace {

// a word for a shell script, single-quoted
std::string shell_word(const std::string& s) {
  std::string q = "'";
  for (char c : s) {
    if (c == '\'') q += "'\\''";
    else q += c;
  }
  return q + "'";
}

// runs a command, returns its exit status and its standard output
std::pair<int, std::string> capture(const std::string& command) {
  std::string out;
  FILE* p = popen(command.c_str(), "r");
  if (!p) return {-1, ""};
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  const int status = pclose(p);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

std::string self_binary() {
  std::error_code ec;
  const fs::path p = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw UserError("cannot find the paddock binary (/proc/self/exe): " + ec.message());
  return p.string();
}

int submit_to_slurm(const SweepSpec& spec, std::size_t points, const std::string& dir, const SlurmOptions& o) {
  const int tasks = static_cast<int>(std::min<std::size_t>(points, o.tasks > 0 ? static_cast<std::size_t>(o.tasks) : 100));
  const std::string abs_dir = fs::absolute(dir).lexically_normal().string();
  const std::string abs_sweep = fs::absolute(spec.path).lexically_normal().string();
  std::ostringstream sc;
  sc << "#!/bin/bash\n"
     << "# paddock sweep " << spec.name << " on Slurm: " << points << " points in " << tasks
     << " array tasks, each one shard (paddock sweep --shard i/n) into the same folder.\n"
     << "# When every task is done: " << self_binary() << " sweep collect " << shell_word(abs_dir) << "\n"
     << "#SBATCH --job-name=paddock-" << spec.name << "\n"
     << "#SBATCH --array=0-" << tasks - 1 << (o.array_limit > 0 ? "%" + std::to_string(o.array_limit) : "") << "\n"
     << "#SBATCH --cpus-per-task=" << o.cpus_per_task << "\n"
     << "#SBATCH --output=" << abs_dir << "/slurm/task_%a.out\n";
  if (!o.partition.empty()) sc << "#SBATCH --partition=" << o.partition << "\n";
  if (!o.time.empty()) sc << "#SBATCH --time=" << o.time << "\n";
  for (const std::string& a : o.sbatch_args) sc << "#SBATCH " << a << "\n";
  sc << "exec " << shell_word(self_binary()) << " sweep " << shell_word(abs_sweep) << " --out " << shell_word(abs_dir)
     << " --shard \"$SLURM_ARRAY_TASK_ID/" << tasks << "\" --jobs \"${SLURM_CPUS_PER_TASK:-" << o.cpus_per_task << "}\"\n";
  const std::string script = abs_dir + "/slurm/sweep.sbatch";
  write_file_atomic(script, sc.str());
  fs::permissions(script, fs::perms::owner_exec | fs::perms::group_exec | fs::perms::others_exec, fs::perm_options::add);
  std::cout << "sweep " << spec.name << ": " << points << " points in " << tasks << " Slurm array tasks\n"
            << "  script      " << script << "\n";
  if (o.dry_run) {
    std::cout << "  (--dry-run: not submitted; submit with: sbatch " << script << ")\n";
    return 0;
  }
  const auto [rc, out] = capture("sbatch --parsable " + shell_word(script) + " 2>&1");
  const std::string job = trim(out.substr(0, out.find_first_of(";\n")));
  if (rc != 0 || !whole(job)) throw UserError("sbatch failed (exit " + std::to_string(rc) + "): " + trim(out));
  write_file_atomic(abs_dir + "/slurm/job_id", job + "\n");
  std::cout << "  submitted   job " << job << "\n";
  if (!o.wait) {
    std::cout << "  when it is done: paddock sweep collect " << dir << "\n";
    return 0;
  }
  // wait for the array to leave the queue (squeue lists pending and running
  // tasks only), showing how many points have their summary
  std::size_t last = static_cast<std::size_t>(-1);
  const bool tty = isatty(fileno(stderr)) != 0;
  while (true) {
    const auto [qrc, q] = capture("squeue -h -j " + job + " -o %i 2>/dev/null");
    std::size_t done = 0;
    for (std::size_t i = 0; i < points; ++i) done += fs::exists(sweep_point_dir(abs_dir, static_cast<int>(i), points) + "/summary.json");
    if (done != last) {
      if (tty) std::cerr << "\rslurm job " << job << ": " << done << "/" << points << " points done   " << std::flush;
      else std::cerr << "slurm job " << job << ": " << done << "/" << points << " points done\n";
      last = done;
    }
    if (qrc == 0 && trim(q).empty()) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(1000));
  }
  if (tty) std::cerr << "\n";
  return collect_sweep(dir);
}

}  // namespace

int run_sweep(const std::string& path, const SweepOptions& options) {
  const SweepSpec spec = load_sweep(path);
  const std::vector<SweepPoint> points = expand_sweep(spec);
  const std::string dir = options.out_dir.empty() ? (fs::path("runs") / spec.name).string() : options.out_dir;
  const bool shard = options.shards > 0;

  // every point's scenario first: a bad value stops the sweep before it starts
  std::vector<Scenario> scenarios;
  scenarios.reserve(points.size());
  for (const SweepPoint& p : points) scenarios.push_back(sweep_point_scenario(spec, p));

  // a fresh folder (or --resume, or a shard of a sweep whose tasks share it)
  const bool exists = fs::exists(fs::path(dir) / "points.csv");
  if (exists && !options.resume && !shard) {
    throw UserError(dir + " holds a sweep already: --resume to finish it, or --out another folder");
  }
  const std::string manifest = manifest_csv(spec, points, scenarios);
  if (exists && read_file(dir + "/points.csv") != manifest) {
    throw UserError(dir + "/points.csv: its points differ from what " + path +
                    " gives now: the sweep file changed; run it into another folder (--out)");
  }
  if (!shard) {
    write_file_atomic(dir + "/points.csv", manifest);
    write_file_atomic(dir + "/sweep.ini", read_file(path));
  } else if (!exists) {
    throw UserError(dir + ": no points.csv here: a shard runs in the folder its sweep was submitted to");
  }
  if (options.slurm) return submit_to_slurm(spec, points.size(), dir, *options.slurm);

  // the tracks, loaded once and shared by the workers (read only)
  const auto [first, last] = shard ? sweep_shard(points.size(), options.shard, options.shards)
                                   : std::pair<std::size_t, std::size_t>{0, points.size()};
  std::map<std::string, std::shared_ptr<const world::TrackModel>> tracks;
  for (std::size_t i = first; i < last; ++i) {
    const Scenario& s = scenarios[i];
    if (tracks.count(s.track_path)) continue;
    world::TrackFile file = load_track_file(s.track_path);
    for (const auto& w : file.warnings) std::cerr << "warning: " << w << "\n";
    tracks[s.track_path] = std::make_shared<const world::TrackModel>(world::build_track(file));
  }

  // what is done already, and that it is this sweep's
  std::vector<std::size_t> todo;
  for (std::size_t i = first; i < last; ++i) {
    const std::string pd = sweep_point_dir(dir, points[i].index, points.size());
    if (fs::exists(pd + "/summary.json")) {
      if (!fs::exists(pd + "/scenario.ini") || read_file(pd + "/scenario.ini") != resolved_ini(scenarios[i])) {
        throw UserError(pd + ": this point's scenario differs from what " + path +
                        " gives now: the sweep file (or a scenario) changed; run it into another folder (--out)");
      }
      continue;
    }
    todo.push_back(i);
  }

  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  const std::size_t jobs = std::min<std::size_t>(options.jobs > 0 ? static_cast<std::size_t>(options.jobs) : cores,
                                                 std::max<std::size_t>(todo.size(), 1));
  const bool tty = isatty(fileno(stderr)) != 0;
  std::cerr << "sweep " << spec.name << (shard ? " shard " + std::to_string(options.shard) + "/" + std::to_string(options.shards) : "")
            << ": " << last - first << " points (" << last - first - todo.size() << " done before), " << jobs
            << (jobs == 1 ? " job" : " jobs") << ", into " << dir << "/\n";

  g_interrupted = 0;
  const auto old_handler = std::signal(SIGINT, on_interrupt);
  std::mutex mu;
  std::atomic<std::size_t> next{0};
  std::size_t done = 0, failed = 0;
  const auto start = std::chrono::steady_clock::now();
  const auto report = [&](const std::string& what) {
    // (under mu)
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double per_min = elapsed > 0.0 ? 60.0 * static_cast<double>(done) / elapsed : 0.0;
    const double eta = done > 0 ? elapsed / static_cast<double>(done) * static_cast<double>(todo.size() - done) : NAN;
    std::ostringstream line;
    line << done << "/" << todo.size() << "  " << fixed(per_min, 1) << " runs/min  ETA " << minutes_text(eta) << "  "
         << failed << (failed == 1 ? " failure" : " failures");
    if (tty) {
      const int width = 30;
      const int filled = todo.empty() ? width : static_cast<int>(width * done / todo.size());
      std::cerr << "\r[" << std::string(static_cast<std::size_t>(filled), '#')
                << std::string(static_cast<std::size_t>(width - filled), '.') << "] " << line.str() << "   " << std::flush;
    } else {
      std::cerr << "sweep: " << line.str() << " (" << what << ")\n";
    }
  };
  const auto worker = [&] {
    while (!g_interrupted) {
      const std::size_t k = next.fetch_add(1);
      if (k >= todo.size()) return;
      const std::size_t i = todo[k];
      const Scenario& s = scenarios[i];
      const std::string pd = sweep_point_dir(dir, points[i].index, points.size());
      std::string what;
      bool ok = true;
      try {
        std::error_code ec;
        fs::remove(pd + "/error.txt", ec);
        const RunResult r = run(s, *tracks.at(s.track_path));
        write_file_atomic(pd + "/scenario.ini", resolved_ini(s));
        write_file_atomic(pd + "/summary.json", summary_json(s, r, check_expectations(s.expect, r)));
        what = "point " + std::to_string(points[i].index) + ": " +
               (r.event.finished ? "finished, " + fixed(r.event.total_time, 3) + " s" : "DNF, " + r.event.dnf_reason);
      } catch (const std::exception& e) {
        ok = false;
        what = "point " + std::to_string(points[i].index) + " failed: " + e.what();
        try {
          write_file_atomic(pd + "/error.txt", std::string(e.what()) + "\n");
        } catch (const std::exception&) {
        }
      }
      const std::lock_guard<std::mutex> lock(mu);
      ++done;
      if (!ok) {
        ++failed;
        if (tty) std::cerr << "\n" << what << "\n";
      }
      report(what);
    }
  };
  std::vector<std::thread> pool;
  for (std::size_t j = 0; j < jobs; ++j) pool.emplace_back(worker);
  for (std::thread& t : pool) t.join();
  std::signal(SIGINT, old_handler);
  if (tty && !todo.empty()) std::cerr << "\n";

  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "sweep " << spec.name << ": " << done << " of " << todo.size() << " points run in " << fixed(elapsed, 1)
            << " s (" << jobs << (jobs == 1 ? " job" : " jobs") << "), " << failed << " failed\n";
  // the tables, from every point's summary (also those of earlier runs); a
  // shard leaves them to `collect`, once every shard is done
  if (!shard) collect_sweep(dir);
  if (g_interrupted) {
    std::cout << "  interrupted: " << todo.size() - done << " points not run; finish with --resume\n";
    return 130;
  }
  return failed == 0 ? 0 : 1;
}

}  // namespace paddock::runner
