// the cost of drawing each figure, PNG encoding included. The default track
// map (FSG 2023, 1600 x 1600 px at 150 dpi, a 3500-point trajectory coloured by
// speed) must take under a second.
//   map:        draw_track_map + encode_png (the figure the runner writes per run)
//   map_ss2:    the map at 2x supersampling instead of 3x
//   map_draw:   draw_track_map alone
//   controller: draw_controller_data (4 panels, 60 s at 100 Hz) + encode_png
//   laps:       draw_lap_chart (12 laps) + encode_png
//   heatmap:    draw_heatmap (20 x 15 cells) + encode_png
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "render/figures.h"

namespace {

using namespace paddock;
using namespace paddock::render;

const std::vector<std::uint8_t>& font() {
  static const std::vector<std::uint8_t> bytes = [] {
    std::ifstream in("/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf", std::ios::binary);
    return std::vector<std::uint8_t>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }();
  return bytes;
}

FigureStyle style(int w, int h) {
  FigureStyle s;
  s.width = w;
  s.height = h;
  s.font = &font();
  return s;
}

// the FSG 2023 cones (tag,x,y rows after # comments), its timekeeping line and
// start, and a lap along the midpoints of each blue cone and its nearest yellow
// one: 3500 points, the speed from the curvature
TrackMapData fsg_map() {
  TrackMapData d;
  d.title = "FSG 2023: trackdrive";
  d.closed = true;
  std::ifstream in(std::string(PADDOCK_SOURCE_DIR) + "/tracks/fsg_2023.csv");
  std::string line;
  std::vector<Vec2> keeping;
  while (std::getline(in, line)) {
    if (line.rfind("# start", 0) == 0) {
      Pose2 p;
      std::istringstream(line.substr(7)) >> p.x >> p.y >> p.yaw;
      d.start = p;
    } else if (line.rfind("# timekeeping", 0) == 0) {
      Vec2 p;
      std::istringstream(line.substr(13)) >> p.x >> p.y;
      keeping.push_back(p);
    }
    if (line.empty() || line[0] == '#' || line.rfind("tag,", 0) == 0) continue;
    std::istringstream ss(line);
    std::string tag, xs, ys;
    std::getline(ss, tag, ',');
    std::getline(ss, xs, ',');
    std::getline(ss, ys, ',');
    Cone c;
    c.position = {std::stod(xs), std::stod(ys)};
    c.color = tag == "blue" ? ConeColor::Blue : tag == "yellow" ? ConeColor::Yellow : ConeColor::BigOrange;
    d.cones.push_back(c);
    if (c.color == ConeColor::Blue) d.left.push_back(c.position);
    if (c.color == ConeColor::Yellow) d.right.push_back(c.position);
  }
  for (std::size_t i = 0; i + 1 < keeping.size(); i += 2) d.gates.push_back({keeping[i], keeping[i + 1]});
  std::vector<Vec2> mid;
  for (const Vec2& b : d.left) {
    Vec2 q = d.right.front();
    for (const Vec2& y : d.right) {
      if (squared_norm(y - b) < squared_norm(q - b)) q = y;
    }
    mid.push_back(0.5 * (b + q));
  }
  double len = 0.0;
  for (std::size_t i = 0; i < mid.size(); ++i) len += distance(mid[i], mid[(i + 1) % mid.size()]);
  for (std::size_t i = 0; i < mid.size(); ++i) {
    const Vec2 a = mid[i], b = mid[(i + 1) % mid.size()];
    const int k = std::max(1, static_cast<int>(std::round(distance(a, b) / (len / 3500.0))));
    for (int j = 0; j < k; ++j) d.trajectory.push_back(a + (b - a) * (static_cast<double>(j) / k));
  }
  const std::size_t m = d.trajectory.size();
  for (std::size_t i = 0; i < m; ++i) {
    const Vec2 a = d.trajectory[(i + m - 8) % m], b = d.trajectory[i], c = d.trajectory[(i + 8) % m];
    const double k = 2.0 * std::abs(cross(b - a, c - b)) / (distance(a, b) * distance(b, c) * distance(a, c) + 1e-9);
    d.speed.push_back(std::clamp(std::sqrt(9.0 / std::max(k, 1e-3)), 4.0, 17.0));
  }
  return d;
}

void BM_RenderMap(benchmark::State& state) {
  const TrackMapData d = fsg_map();
  const FigureStyle s = style(1600, 1600);
  std::size_t bytes = 0;
  for (auto _ : state) {
    const Figure fig = draw_track_map(d, s);
    bytes = encode_png(fig.image).size();
    benchmark::DoNotOptimize(bytes);
  }
  state.counters["png_kB"] = static_cast<double>(bytes) / 1024.0;
}
BENCHMARK(BM_RenderMap)->Name("render/map")->Unit(benchmark::kMillisecond);

// the same at 2x supersampling (4 coverage levels instead of 9)
void BM_RenderMapSs2(benchmark::State& state) {
  const TrackMapData d = fsg_map();
  FigureStyle s = style(1600, 1600);
  s.supersample = 2;
  for (auto _ : state) benchmark::DoNotOptimize(encode_png(draw_track_map(d, s).image).size());
}
BENCHMARK(BM_RenderMapSs2)->Name("render/map_ss2")->Unit(benchmark::kMillisecond);

void BM_RenderMapDraw(benchmark::State& state) {
  const TrackMapData d = fsg_map();
  const FigureStyle s = style(1600, 1600);
  for (auto _ : state) benchmark::DoNotOptimize(draw_track_map(d, s).image.rgba.data());
}
BENCHMARK(BM_RenderMapDraw)->Name("render/map_draw")->Unit(benchmark::kMillisecond);

void BM_RenderController(benchmark::State& state) {
  ControllerData d;
  d.title = "controller data";
  for (int i = 0; i < 6000; ++i) {
    const double t = 0.01 * i;
    d.t.push_back(t);
    d.steer_cmd.push_back(0.3 * std::sin(0.7 * t));
    d.steer.push_back(0.3 * std::sin(0.7 * (t - 0.08)));
    d.v_ref.push_back(11.0 + 4.0 * std::sin(0.35 * t));
    d.v.push_back(11.0 + 4.0 * std::sin(0.35 * (t - 0.3)));
    d.lateral_error.push_back(0.15 * std::sin(1.3 * t));
    d.heading_error.push_back(0.04 * std::cos(0.9 * t));
  }
  d.lap_starts = {0.0, 21.0, 41.5};
  const FigureStyle s = style(1600, 1200);
  for (auto _ : state) benchmark::DoNotOptimize(encode_png(draw_controller_data(d, s).image).size());
}
BENCHMARK(BM_RenderController)->Name("render/controller")->Unit(benchmark::kMillisecond);

void BM_RenderLaps(benchmark::State& state) {
  LapChartData d;
  d.title = "lap times";
  for (int i = 0; i < 12; ++i) {
    d.lap_times.push_back(i == 0 ? 31.4 : 24.0 + 0.3 * std::sin(i));
    d.timed.push_back(i != 0 && i != 11);
    d.doo.push_back(i % 4 == 2 ? 1 : 0);
    d.oc.push_back(i == 7 ? 1 : 0);
  }
  const FigureStyle s = style(1600, 1200);
  for (auto _ : state) benchmark::DoNotOptimize(encode_png(draw_lap_chart(d, s).image).size());
}
BENCHMARK(BM_RenderLaps)->Name("render/laps")->Unit(benchmark::kMillisecond);

void BM_RenderHeatmap(benchmark::State& state) {
  HeatmapData d;
  d.title = "lap time over the controller gains";
  d.x_label = "k_stanley";
  d.y_label = "lookahead [m]";
  d.value_label = "lap time [s]";
  for (int i = 0; i < 20; ++i) d.x.push_back(0.25 * (i + 1));
  for (int j = 0; j < 15; ++j) d.y.push_back(2.0 + 0.5 * j);
  for (int j = 0; j < 15; ++j) {
    for (int i = 0; i < 20; ++i) d.values.push_back(25.0 + 0.02 * (i - 8) * (i - 8) + 0.05 * (j - 6) * (j - 6));
  }
  const FigureStyle s = style(1600, 1200);
  for (auto _ : state) benchmark::DoNotOptimize(encode_png(draw_heatmap(d, s).image).size());
}
BENCHMARK(BM_RenderHeatmap)->Name("render/heatmap")->Unit(benchmark::kMillisecond);

}  // namespace
