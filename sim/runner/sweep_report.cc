#include "sim/runner/sweep_report.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iterator>
#include <limits>
#include <map>
#include <optional>
#include <sstream>

#include "autonomy/common/format.h"
#include "sim/runner/files.h"
#include "sim/runner/report.h"
#include "sim/runner/sweep.h"

namespace paddock::runner {
namespace {

namespace fs = std::filesystem;

// results.csv's rows by column name
struct Results {
  std::vector<std::string> keys;
  std::vector<std::vector<std::string>> rows;
  std::map<std::string, std::size_t> column;
  std::string path;
  const std::string& at(std::size_t row, const std::string& name) const { return rows[row][column.at(name)]; }
};

Results read_results(const std::string& dir) {
  Results r;
  r.path = (fs::path(dir) / "results.csv").string();
  std::istringstream in(read_file(r.path));
  std::string line;
  int number = 0;
  std::vector<std::string> header;
  while (std::getline(in, line)) {
    ++number;
    if (number == 1) {
      header = csv_split(line);
      if (header.size() < 4 || header[0] != "point" || header[1] != "scenario") {
        throw UserError(r.path + ":1: expected the header point,scenario,... of a sweep's results.csv");
      }
      for (std::size_t i = 0; i < header.size(); ++i) r.column[header[i]] = i;
      for (const char* c : {"seed", "finished", "total_time_s", "doo", "tracking_rms_m"}) {
        if (!r.column.count(c)) throw UserError(r.path + ":1: no column '" + c + "'");
      }
      for (std::size_t i = 2; i < r.column.at("seed"); ++i) r.keys.push_back(header[i]);
      continue;
    }
    if (line.empty()) continue;
    std::vector<std::string> cells = csv_split(line);
    if (cells.size() != header.size()) {
      throw UserError(r.path + ":" + std::to_string(number) + ": expected " + std::to_string(header.size()) + " cells, got " +
                      std::to_string(cells.size()));
    }
    r.rows.push_back(std::move(cells));
  }
  return r;
}

bool finished(const Results& r, std::size_t i) { return r.at(i, "finished") == "true"; }

// the configurations in order of first appearance, each run's row indices
std::vector<std::pair<std::vector<std::string>, std::vector<std::size_t>>> group(const Results& r) {
  std::vector<std::pair<std::vector<std::string>, std::vector<std::size_t>>> out;
  std::map<std::vector<std::string>, std::size_t> index;
  for (std::size_t i = 0; i < r.rows.size(); ++i) {
    std::vector<std::string> v;
    for (std::size_t k = 0; k < r.keys.size(); ++k) v.push_back(r.rows[i][2 + k]);
    const auto [it, fresh] = index.emplace(v, out.size());
    if (fresh) out.push_back({v, {}});
    out[it->second].second.push_back(i);
  }
  return out;
}

}  // namespace

SweepTable sweep_table(const std::string& dir) {
  const Results r = read_results(dir);
  SweepTable t;
  t.keys = r.keys;
  for (const auto& [values, rows] : group(r)) {
    SweepConfig c;
    c.values = values;
    c.first_point = static_cast<int>(std::strtol(r.rows[rows.front()][0].c_str(), nullptr, 10));
    double sum = 0.0, rms = 0.0;
    for (std::size_t i : rows) {
      ++c.runs;
      c.cones += static_cast<int>(finite_number(r.at(i, "doo")).value_or(0.0));
      if (!finished(r, i)) continue;
      ++c.finished;
      const double total = finite_number(r.at(i, "total_time_s")).value_or(NAN);
      sum += total;
      c.worst_total = std::max(c.worst_total, total);
      rms += finite_number(r.at(i, "tracking_rms_m")).value_or(NAN);
    }
    c.mean_total = c.finished > 0 ? sum / c.finished : NAN;
    c.mean_rms = c.finished > 0 ? rms / c.finished : NAN;
    t.configs.push_back(c);
  }
  std::stable_sort(t.configs.begin(), t.configs.end(), [](const SweepConfig& a, const SweepConfig& b) {
    const bool fa = a.finished == a.runs, fb = b.finished == b.runs;
    if (fa != fb) return fa;
    if (!fa) return a.finished > b.finished;
    return a.mean_total < b.mean_total;
  });
  return t;
}

std::string sweep_report(const SweepTable& t, int n) {
  std::ostringstream o;
  o << "| rank |";
  for (const std::string& k : t.keys) o << " " << k << " |";
  o << " runs finished | mean total [s] | worst total [s] | cones | mean tracking RMS [m] | first point |\n|---|";
  for (std::size_t k = 0; k < t.keys.size(); ++k) o << "---|";
  o << "---|---|---|---|---|---|\n";
  const auto shown = std::min<std::size_t>(t.configs.size(), static_cast<std::size_t>(std::max(n, 0)));
  for (std::size_t i = 0; i < shown; ++i) {
    const SweepConfig& c = t.configs[i];
    o << "| " << i + 1 << " |";
    for (const std::string& v : c.values) o << " " << v << " |";
    o << " " << c.finished << " / " << c.runs << " | " << (c.finished ? fixed(c.mean_total, 3) : "-") << " | "
      << (c.finished ? fixed(c.worst_total, 3) : "-") << " | " << c.cones << " | " << (c.finished ? fixed(c.mean_rms, 3) : "-")
      << " | " << c.first_point << " |\n";
  }
  if (!t.configs.empty() && !t.keys.empty()) {
    const SweepConfig& best = t.configs.front();
    o << "\nThe best configuration" << (best.finished == best.runs ? "" : " (not every run finished)")
      << ", to paste into a scenario:\n\n```ini\n";
    std::map<std::string, std::vector<std::pair<std::string, std::string>>> by_section;
    std::vector<std::string> order;
    for (std::size_t k = 0; k < t.keys.size(); ++k) {
      const auto dot = t.keys[k].rfind('.');
      const std::string section = t.keys[k].substr(0, dot);
      if (!by_section.count(section)) order.push_back(section);
      by_section[section].push_back({t.keys[k].substr(dot + 1), best.values[k]});
    }
    for (std::size_t s = 0; s < order.size(); ++s) {
      o << (s ? "\n" : "") << "[" << order[s] << "]\n";
      for (const auto& [key, value] : by_section[order[s]]) o << key << " = " << value << "\n";
    }
    o << "```\n";
  }
  return o.str();
}

std::vector<std::string> plot_sweep(const std::string& dir, const PlotOptions& options) {
  const Results r = read_results(dir);
  const SweepTable t = sweep_table(dir);
  const std::vector<std::uint8_t> font = read_font(options);
  const render::FigureStyle style = chart_style(options, font);
  const std::string name = fs::path(fs::absolute(dir).lexically_normal()).filename().string();
  std::vector<std::string> out;
  const auto nan = std::numeric_limits<double>::quiet_NaN();

  // the numeric varied keys
  std::vector<std::size_t> numeric;
  for (std::size_t k = 0; k < r.keys.size(); ++k) {
    bool all = !r.rows.empty();
    for (const auto& row : r.rows) all = all && finite_number(row[2 + k]).has_value();
    if (all) numeric.push_back(k);
  }

  // every run's total time against each key, as a share over the best run
  // of its scenario (so tracks of different lengths share the axis): a
  // marker per run (a NaN between runs breaks the line), one colour per
  // scenario, runs with penalties as red crosses
  std::map<std::string, double> best_of;  // per scenario
  std::vector<std::string> scenario_order;
  for (std::size_t i = 0; i < r.rows.size(); ++i) {
    if (!finished(r, i)) continue;
    const std::string& sc = r.rows[i][1];
    const double total = finite_number(r.at(i, "total_time_s")).value_or(INFINITY);
    if (!best_of.count(sc)) scenario_order.push_back(sc);
    best_of[sc] = std::min(best_of.count(sc) ? best_of[sc] : INFINITY, total);
  }
  static const render::Rgba kPalette[] = {{31, 119, 180, 255}, {255, 127, 14, 255}, {44, 160, 44, 255},
                                          {148, 103, 189, 255}, {140, 86, 75, 255}, {227, 119, 194, 255},
                                          {127, 127, 127, 255}, {188, 189, 34, 255}, {23, 190, 207, 255}};
  for (std::size_t k : numeric) {
    render::LineChartData chart;
    chart.title = name + ": total time against " + r.keys[k] + ", every run";
    chart.x_label = r.keys[k];
    chart.y_label = "total time over its scenario's best run [%]";
    chart.include_zero = true;
    std::vector<render::LineSeries> per_scenario;
    for (std::size_t j = 0; j < scenario_order.size(); ++j) {
      per_scenario.push_back({scenario_order[j], {}, {}, kPalette[j % std::size(kPalette)], render::Marker::Circle});
    }
    render::LineSeries penalised{"with penalties", {}, {}, {214, 39, 40, 255}, render::Marker::Cross};
    for (std::size_t i = 0; i < r.rows.size(); ++i) {
      if (!finished(r, i)) continue;
      const std::string& sc = r.rows[i][1];
      const double x = *finite_number(r.rows[i][2 + k]);
      const double y = 100.0 * (finite_number(r.at(i, "total_time_s")).value_or(nan) / best_of[sc] - 1.0);
      const bool pen = finite_number(r.column.count("penalty_s") ? r.at(i, "penalty_s") : "").value_or(0.0) > 0.0;
      const auto j = static_cast<std::size_t>(std::find(scenario_order.begin(), scenario_order.end(), sc) - scenario_order.begin());
      render::LineSeries& s = pen ? penalised : per_scenario[j];
      s.x.insert(s.x.end(), {x, nan});
      s.y.insert(s.y.end(), {y, nan});
    }
    per_scenario.push_back(penalised);
    for (const render::LineSeries& s : per_scenario) {
      if (!s.x.empty()) chart.series.push_back(s);
    }
    if (chart.series.empty()) continue;
    std::string file = r.keys[k];
    std::replace(file.begin(), file.end(), '.', '_');
    out.push_back((fs::path(dir) / "plots" / ("total_time_" + file + ".png")).string());
    write_png(out.back(), render::draw_line_chart(chart, style).image);
  }

  // the first two numeric keys: each cell the mean total time of its
  // configurations (over the other keys, scenarios and seeds)
  if (numeric.size() >= 2) {
    const std::size_t a = numeric[0], b = numeric[1];
    std::vector<double> xs, ys;
    for (const auto& row : r.rows) {
      xs.push_back(*finite_number(row[2 + a]));
      ys.push_back(*finite_number(row[2 + b]));
    }
    std::sort(xs.begin(), xs.end());
    xs.erase(std::unique(xs.begin(), xs.end()), xs.end());
    std::sort(ys.begin(), ys.end());
    ys.erase(std::unique(ys.begin(), ys.end()), ys.end());
    if (xs.size() * ys.size() <= 10000) {
      std::vector<double> sum(xs.size() * ys.size(), 0.0), count(xs.size() * ys.size(), 0.0);
      std::vector<bool> dnf(xs.size() * ys.size(), false);
      for (std::size_t i = 0; i < r.rows.size(); ++i) {
        const auto ix = static_cast<std::size_t>(std::lower_bound(xs.begin(), xs.end(), *finite_number(r.rows[i][2 + a])) - xs.begin());
        const auto iy = static_cast<std::size_t>(std::lower_bound(ys.begin(), ys.end(), *finite_number(r.rows[i][2 + b])) - ys.begin());
        const std::size_t cell = iy * xs.size() + ix;
        if (!finished(r, i)) {
          dnf[cell] = true;
          continue;
        }
        sum[cell] += finite_number(r.at(i, "total_time_s")).value_or(nan);
        count[cell] += 1.0;
      }
      render::HeatmapData h;
      h.title = name + ": mean total time (a cell with a DNF: none)";
      h.x_label = r.keys[a];
      h.y_label = r.keys[b];
      h.value_label = "mean total time [s]";
      h.x = xs;
      h.y = ys;
      for (std::size_t c = 0; c < sum.size(); ++c) h.values.push_back(count[c] > 0.0 && !dnf[c] ? sum[c] / count[c] : nan);
      out.push_back((fs::path(dir) / "plots" / "heatmap.png").string());
      write_png(out.back(), render::draw_heatmap(h, style).image);
    }
  }

  // the configurations' mean total time against their mean tracking RMS
  // (all runs finished): the Pareto front (no other is both faster and
  // tighter) as a line, the best (fastest) marked
  {
    render::LineChartData chart;
    chart.title = name + ": configurations, mean total time against mean tracking RMS";
    chart.x_label = "mean tracking RMS [m]";
    chart.y_label = "mean total time [s]";
    chart.include_zero = false;
    render::LineSeries all{"configuration", {}, {}, {150, 150, 150, 255}, render::Marker::Circle};
    render::LineSeries coned{"cones hit", {}, {}, {214, 39, 40, 255}, render::Marker::Cross};
    std::vector<std::pair<double, double>> pts;
    for (const SweepConfig& c : t.configs) {
      if (c.finished != c.runs || c.runs == 0) continue;
      render::LineSeries& s = c.cones > 0 ? coned : all;
      s.x.insert(s.x.end(), {c.mean_rms, nan});
      s.y.insert(s.y.end(), {c.mean_total, nan});
      pts.push_back({c.mean_rms, c.mean_total});
    }
    if (!pts.empty()) {
      std::sort(pts.begin(), pts.end());
      render::LineSeries front{"Pareto front", {}, {}, {31, 119, 180, 255}, render::Marker::Square};
      double best_y = INFINITY;
      for (const auto& [x, y] : pts) {
        if (y < best_y) {
          front.x.push_back(x);
          front.y.push_back(y);
          best_y = y;
        }
      }
      const SweepConfig& best = t.configs.front();
      render::LineSeries mark{"best: " + (best.values.empty() ? std::string("-") : [&] {
        std::string s;
        for (std::size_t k = 0; k < best.values.size(); ++k) s += (k ? ", " : "") + best.values[k];
        return s;
      }()), {best.mean_rms}, {best.mean_total}, {44, 160, 44, 255}, render::Marker::Triangle};
      for (render::LineSeries* s : {&all, &coned, &front, &mark}) {
        if (!s->x.empty()) chart.series.push_back(*s);
      }
      out.push_back((fs::path(dir) / "plots" / "pareto.png").string());
      write_png(out.back(), render::draw_line_chart(chart, style).image);
    }
  }
  return out;
}

}  // namespace paddock::runner
