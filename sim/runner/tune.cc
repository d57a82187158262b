#include "sim/runner/tune.h"

#include <nlopt.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>

#include "autonomy/common/format.h"
#include "sim/runner/files.h"
#include "sim/runner/report.h"
#include "sim/runner/scenario.h"
#include "sim/runner/simulation.h"
#include "sim/runner/sweep.h"

namespace paddock::runner {
namespace {

namespace fs = std::filesystem;

double number_of(const IniEntry& e, double lo, double hi, const std::string& what) {
  const auto v = finite_number(e.value);
  if (!v || *v < lo || *v > hi) {
    throw UserError(e.where() + ": [tune] " + e.key + ": expected " + what + ", got '" + e.value + "'");
  }
  return *v;
}

std::int64_t whole_of(const IniEntry& e, std::int64_t lo, std::int64_t hi) {
  char* end = nullptr;
  const long long v = std::strtoll(e.value.c_str(), &end, 10);
  if (e.value.empty() || *end != '\0' || v < lo || v > hi) {
    throw UserError(e.where() + ": [tune] " + e.key + ": expected a whole number from " + std::to_string(lo) + " to " +
                    std::to_string(hi) + ", got '" + e.value + "'");
  }
  return static_cast<std::int64_t>(v);
}

TuneKey parse_key(const IniEntry& e) {
  TuneKey k;
  k.where = e;
  const auto dot = e.key.rfind('.');
  if (dot == std::string::npos || dot == 0 || dot + 1 == e.key.size()) {
    throw UserError(e.where() + ": [optimise] " + e.key + ": expected section.key (e.g. control.stanley.k)");
  }
  k.section = e.key.substr(0, dot);
  k.key = e.key.substr(dot + 1);
  const std::string& v = e.value;
  const bool lin = v.rfind("bounds(", 0) == 0, log = v.rfind("logbounds(", 0) == 0;
  if ((!lin && !log) || v.back() != ')') {
    throw UserError(e.where() + ": [optimise] " + e.key + ": expected bounds(low, high) or logbounds(low, high), got '" + v + "'");
  }
  const std::size_t open = v.find('(');
  const std::vector<std::string> args = split_list(v.substr(open + 1, v.size() - open - 2));
  const auto lo = args.size() == 2 ? finite_number(args[0]) : std::nullopt;
  const auto hi = args.size() == 2 ? finite_number(args[1]) : std::nullopt;
  if (!lo || !hi || !(*lo < *hi) || (log && !(*lo > 0.0))) {
    throw UserError(e.where() + ": [optimise] " + e.key + ": expected " + (log ? "0 < low < high" : "low < high") +
                    " in '" + v + "'");
  }
  k.lo = *lo;
  k.hi = *hi;
  k.log = log;
  return k;
}

// the search runs in u in [0, 1] per key: linear or logarithmic in the value
double value_of(const TuneKey& k, double u) {
  u = std::min(1.0, std::max(0.0, u));
  const double x = k.log ? std::exp(std::log(k.lo) + u * (std::log(k.hi) - std::log(k.lo))) : k.lo + u * (k.hi - k.lo);
  return std::min(k.hi, std::max(k.lo, x));
}
double u_of(const TuneKey& k, double x) {
  x = std::min(k.hi, std::max(k.lo, x));
  return k.log ? (std::log(x) - std::log(k.lo)) / (std::log(k.hi) - std::log(k.lo)) : (x - k.lo) / (k.hi - k.lo);
}

nlopt_algorithm algorithm_of(const std::string& name) {
  if (name == "sbplx") return NLOPT_LN_SBPLX;
  if (name == "bobyqa") return NLOPT_LN_BOBYQA;
  if (name == "neldermead") return NLOPT_LN_NELDERMEAD;
  if (name == "cobyla") return NLOPT_LN_COBYLA;
  return NLOPT_GN_CRS2_LM;  // "crs2"
}

// the value of `key` in a scenario's resolved INI text
std::string resolved_value(const std::string& ini, const TuneKey& k) {
  std::istringstream in(ini);
  std::string line, section;
  while (std::getline(in, line)) {
    if (!line.empty() && line[0] == '[') {
      section = line.substr(1, line.find(']') - 1);
      continue;
    }
    if (section != k.section) continue;
    const auto eq = line.find(" = ");
    if (eq != std::string::npos && line.substr(0, eq) == k.key) {
      const auto semi = line.find("  ;", eq);
      return line.substr(eq + 3, semi == std::string::npos ? std::string::npos : semi - eq - 3);
    }
  }
  return "";
}

struct Evaluation {
  std::vector<double> values;
  double objective = 0.0;
  std::vector<double> costs;       // per run
  std::vector<std::string> notes;  // per run: total time, cones, or why not finished
};

class Tuner {
 public:
  Tuner(const TuneSpec& spec, const TuneOptions& options) : spec_(spec), options_(options) {
    for (const std::string& s : spec_.scenarios) base_.push_back(read_ini_file(s));
    const std::size_t seeds = std::max<std::size_t>(spec_.seeds.size(), 1);
    for (std::size_t s = 0; s < spec_.scenarios.size(); ++s) {
      for (std::size_t k = 0; k < seeds; ++k) runs_.push_back({s, spec_.seeds.empty() ? std::optional<std::uint64_t>() : spec_.seeds[k]});
    }
  }

  // the scenario of run r with the keys at `values`; a bad value is reported
  // on its [optimise] line
  Scenario scenario(std::size_t r, const std::vector<double>* values) const {
    std::vector<IniEntry> entries = base_[runs_[r].scenario];
    entries.insert(entries.end(), spec_.common.begin(), spec_.common.end());
    if (values) {
      for (std::size_t i = 0; i < spec_.keys.size(); ++i) {
        IniEntry e = spec_.keys[i].where;
        e.section = spec_.keys[i].section;
        e.key = spec_.keys[i].key;
        e.value = fmt((*values)[i]);
        entries.push_back(e);
      }
    }
    if (runs_[r].seed) {
      IniEntry e = spec_.seeds_where;
      e.section = "scenario";
      e.key = "seed";
      e.value = std::to_string(*runs_[r].seed);
      entries.push_back(e);
    }
    Scenario sc = load_scenario_entries(entries, spec_.scenarios[runs_[r].scenario]);
    if (sc.hal.transport == Transport::Udp)
      throw UserError(spec_.scenarios[runs_[r].scenario] +
                      ": [hal] transport = udp runs one simulation against one car binary; a tune runs many side by side (use memory or wire)");
    return sc;
  }

  // the keys' values in the scenarios as the tune file leaves them (the first
  // scenario's), clamped into their bounds
  std::vector<double> start() const {
    const std::string ini = resolved_ini(scenario(0, nullptr));
    std::vector<double> x;
    for (const TuneKey& k : spec_.keys) {
      const std::string text = resolved_value(ini, k);
      if (text.empty()) throw UserError(k.where.where() + ": [optimise] " + k.name() + " is not a scenario key (paddock keys lists them)");
      const auto v = finite_number(text);
      if (!v) throw UserError(k.where.where() + ": [optimise] " + k.name() + " is no number in the scenario (it has '" + text + "')");
      x.push_back(std::min(k.hi, std::max(k.lo, *v)));
    }
    return x;
  }

  const Evaluation& evaluate(const std::vector<double>& values) {
    // (NLopt may ask for a point again)
    for (const Evaluation& e : evals_) {
      if (e.values == values) return e;
    }
    Evaluation ev;
    ev.values = values;
    ev.costs.assign(runs_.size(), 0.0);
    ev.notes.assign(runs_.size(), "");
    // a point the scenario refuses (a constraint between keys the bounds
    // cannot say, such as k_max >= k_min) costs as a DNF
    std::vector<std::optional<Scenario>> scenarios(runs_.size());
    for (std::size_t r = 0; r < runs_.size(); ++r) {
      try {
        scenarios[r] = scenario(r, &values);
      } catch (const UserError& e) {
        ev.costs[r] = spec_.dnf_cost;
        const std::string what = e.what();
        ev.notes[r] = "refused: " + what.substr(what.find(": ") == std::string::npos ? 0 : what.find(": ") + 2);
      }
    }
    // the runs at once, `jobs` threads
    const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
    const std::size_t jobs = std::min<std::size_t>(options_.jobs > 0 ? static_cast<std::size_t>(options_.jobs) : cores, runs_.size());
    std::vector<std::thread> pool;
    std::vector<std::string> errors(runs_.size());
    for (std::size_t j = 0; j < jobs; ++j) {
      pool.emplace_back([&, j] {
        for (std::size_t r = j; r < runs_.size(); r += jobs) {
          if (!scenarios[r]) continue;
          try {
            const RunResult res = run(*scenarios[r], track(scenarios[r]->track_path));
            ev.costs[r] = cost(res);
            ev.notes[r] = res.event.finished ? fixed(res.event.total_time, 3) + " s, " + std::to_string(res.event.doo) + " DOO"
                                             : "DNF (" + res.event.dnf_reason + ")";
          } catch (const std::exception& e) {
            errors[r] = e.what();
          }
        }
      });
    }
    for (std::thread& t : pool) t.join();
    for (const std::string& e : errors) {
      if (!e.empty()) throw UserError("a run of the tune failed: " + e);
    }
    double sum = 0.0, weights = 0.0;
    for (std::size_t r = 0; r < runs_.size(); ++r) {
      const double w = spec_.weights[runs_[r].scenario];
      sum += w * ev.costs[r];
      weights += w;
    }
    ev.objective = sum / weights;
    evals_.push_back(ev);
    return evals_.back();
  }

  double cost(const RunResult& r) const {
    if (!r.event.finished) return spec_.dnf_cost;
    return r.event.total_time + spec_.tracking_weight * r.tracking.rms + spec_.cone_weight * r.event.doo;
  }

  const std::vector<Evaluation>& evaluations() const { return evals_; }
  std::size_t runs() const { return runs_.size(); }
  std::string run_name(std::size_t r) const {
    std::string n = fs::path(spec_.scenarios[runs_[r].scenario]).stem().string();
    if (runs_[r].seed) n += " seed " + std::to_string(*runs_[r].seed);
    return n;
  }

 private:
  const world::TrackModel& track(const std::string& path) {
    const std::lock_guard<std::mutex> lock(tracks_mu_);
    auto it = tracks_.find(path);
    if (it == tracks_.end()) it = tracks_.emplace(path, std::make_unique<world::TrackModel>(world::build_track(load_track_file(path)))).first;
    return *it->second;
  }

  struct Run {
    std::size_t scenario;
    std::optional<std::uint64_t> seed;
  };
  const TuneSpec& spec_;
  const TuneOptions& options_;
  std::vector<std::vector<IniEntry>> base_;
  std::vector<Run> runs_;
  std::vector<Evaluation> evals_;
  std::mutex tracks_mu_;
  std::map<std::string, std::unique_ptr<world::TrackModel>> tracks_;
};

struct Context {
  Tuner* tuner = nullptr;
  const TuneSpec* spec = nullptr;
  int max_evals = 0;
  std::vector<double> start, start_u;  // the start exactly, where u is the start's
  double best = INFINITY;
  int best_eval = 0;
  std::string error;
};

// the keys' values to 5 significant digits (the files have them exactly)
std::string values_text(const TuneSpec& spec, const std::vector<double>& x) {
  std::string s;
  for (std::size_t i = 0; i < x.size(); ++i) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.5g", x[i]);
    s += (i ? "  " : "") + spec.keys[i].key + "=" + buf;
  }
  return s;
}

double objective(unsigned n, const double* u, double* grad, void* data) {
  (void)grad;  // derivative-free algorithms only
  auto* c = static_cast<Context*>(data);
  std::vector<double> x(n);
  for (unsigned i = 0; i < n; ++i) x[i] = u[i] == c->start_u[i] ? c->start[i] : value_of(c->spec->keys[i], u[i]);
  try {
    const std::size_t before = c->tuner->evaluations().size();
    const Evaluation& e = c->tuner->evaluate(x);
    if (c->tuner->evaluations().size() > before) {
      const int k = static_cast<int>(c->tuner->evaluations().size());
      if (e.objective < c->best) {
        c->best = e.objective;
        c->best_eval = k;
      }
      std::cerr << "tune: eval " << k << "/" << c->max_evals << "  " << values_text(*c->spec, x) << "  -> "
                << fixed(e.objective, 3) << "  (best " << fixed(c->best, 3) << " at eval " << c->best_eval << ")\n";
    }
    return e.objective;
  } catch (const std::exception& ex) {
    c->error = ex.what();
    return HUGE_VAL;
  }
}

}  // namespace

TuneSpec load_tune(const std::string& path) {
  TuneSpec spec;
  spec.path = path;
  spec.name = fs::path(path).stem().string();
  const std::vector<IniEntry> entries = read_ini_file(path);
  std::optional<IniEntry> weights;
  for (const IniEntry& e : entries) {
    if (e.section == "optimise") {
      spec.keys.push_back(parse_key(e));
      continue;
    }
    if (e.section != "tune") {
      spec.common.push_back(e);
      continue;
    }
    if (e.key == "scenarios") {
      spec.scenarios = scenario_list(e);
    } else if (e.key == "weights") {
      weights = e;
    } else if (e.key == "seeds") {
      spec.seeds = seed_list(e);
      spec.seeds_where = e;
    } else if (e.key == "algorithm") {
      if (e.value != "sbplx" && e.value != "bobyqa" && e.value != "neldermead" && e.value != "cobyla" && e.value != "crs2") {
        throw UserError(e.where() + ": [tune] algorithm: expected sbplx, bobyqa, neldermead, cobyla or crs2, got '" + e.value + "'");
      }
      spec.algorithm = e.value;
    } else if (e.key == "max_evals") {
      spec.max_evals = static_cast<int>(whole_of(e, 1, 100000));
    } else if (e.key == "rel_tol") {
      spec.rel_tol = number_of(e, 0.0, 1.0, "a number in [0, 1]");
    } else if (e.key == "initial_step") {
      spec.initial_step = number_of(e, 1e-6, 1.0, "a share of the range in (0, 1]");
    } else if (e.key == "nlopt_seed") {
      spec.nlopt_seed = static_cast<std::uint64_t>(whole_of(e, 0, 1000000000000000));
    } else if (e.key == "tracking_weight") {
      spec.tracking_weight = number_of(e, 0.0, 1e6, "s per m, >= 0");
    } else if (e.key == "cone_weight") {
      spec.cone_weight = number_of(e, 0.0, 1e6, "s per cone, >= 0");
    } else if (e.key == "dnf_cost") {
      spec.dnf_cost = number_of(e, 0.0, 1e9, "s, >= 0");
    } else {
      throw UserError(e.where() + ": [tune] unknown key '" + e.key +
                      "'; expected scenarios, weights, seeds, algorithm, max_evals, rel_tol, initial_step, nlopt_seed, "
                      "tracking_weight, cone_weight or dnf_cost");
    }
  }
  if (spec.scenarios.empty()) throw UserError(path + ": [tune] scenarios is not set: expected the scenario files of the objective");
  if (spec.keys.empty()) throw UserError(path + ": no [optimise] keys: expected section.key = bounds(low, high)");
  spec.weights.assign(spec.scenarios.size(), 1.0);
  if (weights) {
    const std::vector<std::string> w = split_list(weights->value);
    if (w.size() != spec.scenarios.size()) {
      throw UserError(weights->where() + ": [tune] weights: expected one per scenario (" + std::to_string(spec.scenarios.size()) +
                      "), got " + std::to_string(w.size()));
    }
    for (std::size_t i = 0; i < w.size(); ++i) {
      const auto v = finite_number(w[i]);
      if (!v || *v < 0.0) throw UserError(weights->where() + ": [tune] weights: '" + w[i] + "' is no number >= 0");
      spec.weights[i] = *v;
    }
    if (std::all_of(spec.weights.begin(), spec.weights.end(), [](double x) { return x == 0.0; })) {
      throw UserError(weights->where() + ": [tune] weights: at least one must be > 0");
    }
  }
  for (std::size_t i = 0; i < spec.keys.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (spec.keys[i].name() == spec.keys[j].name()) {
        throw UserError(spec.keys[i].where.where() + ": [optimise] " + spec.keys[i].name() + " is already at line " +
                        std::to_string(spec.keys[j].where.line));
      }
    }
  }
  return spec;
}

TuneResult run_tune(const std::string& path, const TuneOptions& options) {
  const TuneSpec spec = load_tune(path);
  const std::string dir = options.out_dir.empty() ? (fs::path("runs") / spec.name).string() : options.out_dir;
  Tuner tuner(spec, options);
  TuneResult result;
  // the keys exist and take numbers: every scenario builds with the start
  // (a bad key is a file:line error now, not after the first runs); a point
  // refused later (a constraint between keys) costs as a DNF
  for (std::size_t r = 0; r < tuner.runs(); ++r) tuner.scenario(r, nullptr);
  result.start = tuner.start();
  for (std::size_t r = 0; r < tuner.runs(); ++r) tuner.scenario(r, &result.start);
  const int max_evals = options.max_evals > 0 ? options.max_evals : spec.max_evals;
  std::cerr << "tune " << spec.name << ": " << spec.keys.size() << " keys, " << tuner.runs() << " runs an evaluation, "
            << spec.algorithm << ", at most " << max_evals << " evaluations, into " << dir << "/\n";

  const auto n = static_cast<unsigned>(spec.keys.size());
  nlopt_srand(spec.nlopt_seed);
  nlopt_opt opt = nlopt_create(algorithm_of(spec.algorithm), n);
  std::vector<double> lo(n, 0.0), hi(n, 1.0), u(n), step(n, spec.initial_step);
  for (unsigned i = 0; i < n; ++i) u[i] = u_of(spec.keys[i], result.start[i]);
  // a start on a bound steps inwards
  for (unsigned i = 0; i < n; ++i) {
    if (u[i] + step[i] > 1.0 && u[i] - step[i] < 0.0) step[i] = std::max(u[i], 1.0 - u[i]);
  }
  Context ctx;
  ctx.tuner = &tuner;
  ctx.spec = &spec;
  ctx.max_evals = max_evals;
  ctx.start = result.start;
  ctx.start_u = u;
  nlopt_set_lower_bounds(opt, lo.data());
  nlopt_set_upper_bounds(opt, hi.data());
  nlopt_set_min_objective(opt, objective, &ctx);
  nlopt_set_maxeval(opt, max_evals);
  nlopt_set_ftol_rel(opt, spec.rel_tol);
  nlopt_set_initial_step(opt, step.data());
  double best_u_value = 0.0;
  const auto start = std::chrono::steady_clock::now();
  const nlopt_result rc = nlopt_optimize(opt, u.data(), &best_u_value);
  nlopt_destroy(opt);
  if (!ctx.error.empty()) throw UserError(ctx.error);
  switch (rc) {
    case NLOPT_MAXEVAL_REACHED: result.stop_reason = "the evaluation budget"; break;
    case NLOPT_FTOL_REACHED: result.stop_reason = "rel_tol reached"; break;
    case NLOPT_XTOL_REACHED: result.stop_reason = "the step became negligible"; break;
    case NLOPT_SUCCESS:
    case NLOPT_STOPVAL_REACHED: result.stop_reason = "converged"; break;
    case NLOPT_ROUNDOFF_LIMITED: result.stop_reason = "round-off"; break;
    default: result.stop_reason = "NLopt error " + std::to_string(static_cast<int>(rc)); break;
  }

  // the best evaluation (the first of equals), and the start's
  const std::vector<Evaluation>& evals = tuner.evaluations();
  if (evals.empty()) throw UserError("the tune made no evaluation (" + result.stop_reason + ")");
  std::size_t best = 0;
  for (std::size_t k = 1; k < evals.size(); ++k) {
    if (evals[k].objective < evals[best].objective) best = k;
  }
  result.best = evals[best].values;
  result.best_objective = evals[best].objective;
  result.start_objective = evals.front().objective;
  result.evaluations = static_cast<int>(evals.size());

  std::ostringstream csv;
  csv << "eval";
  for (const TuneKey& k : spec.keys) csv << "," << csv_cell(k.name());
  csv << ",objective";
  for (std::size_t r = 0; r < tuner.runs(); ++r) csv << "," << csv_cell("cost " + tuner.run_name(r)) << "," << csv_cell("result " + tuner.run_name(r));
  csv << "\n";
  for (std::size_t k = 0; k < evals.size(); ++k) {
    csv << k + 1;
    for (double v : evals[k].values) csv << "," << fmt(v);
    csv << "," << fmt(evals[k].objective);
    for (std::size_t r = 0; r < tuner.runs(); ++r) csv << "," << fmt(evals[k].costs[r]) << "," << csv_cell(evals[k].notes[r]);
    csv << "\n";
  }
  write_file_atomic(dir + "/evaluations.csv", csv.str());

  std::ostringstream ini;
  ini << "; paddock tune " << spec.name << ": the best of " << evals.size() << " evaluations (eval " << best + 1
      << "), objective " << fmt(result.best_objective) << " against " << fmt(result.start_objective) << " at the start\n"
      << "; from " << path << "; include it in a scenario after the scenario's other includes\n";
  std::vector<std::size_t> order(spec.keys.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return spec.keys[a].section < spec.keys[b].section; });
  std::string section;
  for (std::size_t i : order) {
    if (spec.keys[i].section != section) {
      section = spec.keys[i].section;
      ini << "\n[" << section << "]\n";
    }
    ini << spec.keys[i].key << " = " << fmt(result.best[i]) << "  ; start " << fmt(result.start[i]) << "\n";
  }
  write_file_atomic(dir + "/best.ini", ini.str());

  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "tune " << spec.name << ": " << evals.size() << " evaluations in " << fixed(wall, 1) << " s, stopped by "
            << result.stop_reason << "\n"
            << "  start       " << values_text(spec, result.start) << "  -> " << fixed(result.start_objective, 3) << "\n"
            << "  best        " << values_text(spec, result.best) << "  -> " << fixed(result.best_objective, 3) << " (eval "
            << best + 1 << ")\n";
  for (std::size_t r = 0; r < tuner.runs(); ++r) std::cout << "    " << tuner.run_name(r) << ": " << evals[best].notes[r] << "\n";
  std::cout << "  best.ini    " << dir << "/best.ini\n"
            << "  table       " << dir << "/evaluations.csv\n";
  return result;
}

}  // namespace paddock::runner
