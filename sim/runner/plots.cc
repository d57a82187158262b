#include "sim/runner/plots.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <nlohmann/json.hpp>

#include "render/figures.h"
#include "sim/runner/files.h"
#include "sim/runner/report.h"
#include "sim/runner/scenario.h"
#include "sim/vehicle/vehicle.h"
#include "sim/world/track.h"
#include "sim/runner/summary_reader.h"
#include "sim/world/venue.h"

namespace paddock::runner {
namespace {

SummaryLaps read_summary(const std::string& path) { return parse_summary(read_file(path), path); }

// the layers of DIR/plan.json, when the run planned from cones
void add_plan_layers(const std::string& path, render::TrackMapData& map) {
  if (!std::filesystem::exists(path)) return;
  const std::string text = read_file(path);
  try {
    const nlohmann::json j = nlohmann::json::parse(text);
    auto points = [](const nlohmann::json& a) {
      std::vector<Vec2> out;
      for (const auto& p : a) out.push_back({p.at(0).get<double>(), p.at(1).get<double>()});
      return out;
    };
    render::MapLayer tri;
    tri.kind = render::MapLayer::Kind::Segments;
    tri.label = "Delaunay triangulation";
    tri.color = {170, 170, 170, 255};
    tri.size = 0.5;
    for (const auto& e : j.at("triangulation")) {
      tri.points.push_back({e.at(0).get<double>(), e.at(1).get<double>()});
      tri.points.push_back({e.at(2).get<double>(), e.at(3).get<double>()});
    }
    render::MapLayer mid;
    mid.kind = render::MapLayer::Kind::Points;
    mid.label = "edge midpoints";
    mid.color = {230, 120, 200, 255};
    mid.size = 2.0;
    mid.points = points(j.at("midpoints"));
    render::MapLayer centre;
    centre.kind = render::MapLayer::Kind::Points;
    centre.label = "centreline points";
    centre.color = {0, 160, 60, 255};
    centre.size = 3.5;
    centre.points = points(j.at("centreline"));
    for (auto* layer : {&tri, &mid, &centre})
      if (!layer->points.empty()) map.layers.push_back(*layer);
    for (const auto& c : j.at("mapped_cones")) {
      ConeColor color = ConeColor::Unknown;
      const std::string tag = c.at(2).get<std::string>();
      for (ConeColor k : {ConeColor::Blue, ConeColor::Yellow, ConeColor::SmallOrange, ConeColor::BigOrange})
        if (tag == cone_tag(k)) color = k;
      map.estimated_cones.push_back({{c.at(0).get<double>(), c.at(1).get<double>()}, color});
    }
  } catch (const nlohmann::json::exception& e) {
    throw UserError(path + ": not a paddock plan: " + e.what());
  }
}

ConeColor color_of_tag(const std::string& tag) {
  for (ConeColor k : {ConeColor::Blue, ConeColor::Yellow, ConeColor::SmallOrange, ConeColor::BigOrange})
    if (tag == cone_tag(k)) return k;
  return ConeColor::Unknown;
}

// DIR/perception.json (and camera.png) -> the LiDAR view and the camera view
std::vector<std::string> plot_perception(const std::string& dir, const render::FigureStyle& map_style,
                                         const render::FigureStyle& chart_style) {
  const std::string path = dir + "/perception.json";
  std::vector<std::string> out;
  if (!std::filesystem::exists(path)) return out;
  render::LidarViewData lidar;
  render::CameraViewData camera;
  bool has_camera = false;
  try {
    const nlohmann::json j = nlohmann::json::parse(read_file(path));
    auto cones = [](const nlohmann::json& a) {
      std::vector<Cone> cs;
      for (const auto& c : a) cs.push_back({{c.at(0).get<double>(), c.at(1).get<double>()}, color_of_tag(c.at(2).get<std::string>())});
      return cs;
    };
    char when[32];
    std::snprintf(when, sizeof when, "%.1f", j.at("t").get<double>());
    lidar.title = "LiDAR scan at t = " + std::string(when) + " s: ground, non-ground, cones";
    for (const auto& p : j.at("points"))
      lidar.points.push_back({p.at(0).get<float>(), p.at(1).get<float>(), p.at(3).get<std::uint8_t>()});
    lidar.detected = cones(j.at("detected"));
    lidar.truth = cones(j.at("truth"));
    if (j.contains("camera")) {
      const auto& c = j.at("camera");
      has_camera = true;
      camera.title = "camera at t = " + std::string(when) + " s: detections and projected LiDAR cluster centres";
      camera.width = c.at("width").get<int>();
      camera.height = c.at("height").get<int>();
      for (const auto& b : c.at("boxes"))
        camera.boxes.push_back({b.at(0).get<double>(), b.at(1).get<double>(), b.at(2).get<double>(), b.at(3).get<double>(),
                                color_of_tag(b.at(4).get<std::string>())});
      for (const auto& p : c.at("projected")) camera.projected.push_back({p.at(0).get<double>(), p.at(1).get<double>()});
      for (const auto& p : c.at("dropped")) camera.dropped.push_back({p.at(0).get<double>(), p.at(1).get<double>()});
      // the image lies in the run's folder: a name, never a path out of it
      const std::string image = c.at("image").get<std::string>();
      if (image.empty() || image.find('/') != std::string::npos || image == "." || image == "..")
        throw UserError(dir + "/perception.json: camera.image '" + image + "': expected a file name in " + dir);
      const std::string png = read_file(dir + "/" + image);
      const render::Image img = render::decode_png(std::vector<std::uint8_t>(png.begin(), png.end()));
      if (img.width != camera.width || img.height != camera.height)
        throw UserError(dir + "/camera.png: " + std::to_string(img.width) + "x" + std::to_string(img.height) +
                        " px, perception.json says " + std::to_string(camera.width) + "x" + std::to_string(camera.height));
      camera.rgb.resize(static_cast<std::size_t>(img.width) * static_cast<std::size_t>(img.height) * 3);
      for (std::size_t i = 0; i < camera.rgb.size() / 3; ++i)
        for (std::size_t k = 0; k < 3; ++k) camera.rgb[3 * i + k] = img.rgba[4 * i + k];
    }
  } catch (const nlohmann::json::exception& e) {
    throw UserError(path + ": not a paddock perception snapshot: " + e.what());
  }
  out.push_back(dir + "/lidar_view.png");
  write_png(out.back(), render::draw_lidar_view(lidar, map_style).image);
  if (has_camera) {
    render::FigureStyle style = chart_style;
    // the image's aspect, plus room for the title and legend
    style.height = std::max(400, static_cast<int>(style.width * camera.height / std::max(1, camera.width)) + 300);
    out.push_back(dir + "/camera_view.png");
    write_png(out.back(), render::draw_camera_view(camera, style).image);
  }
  return out;
}

}  // namespace

std::vector<std::uint8_t> read_font(const PlotOptions& options) {
  const std::string text = read_file(options.font_path);
  return std::vector<std::uint8_t>(text.begin(), text.end());
}

render::FigureStyle map_style(const PlotOptions& options, const std::vector<std::uint8_t>& font) {
  render::FigureStyle style;
  style.width = style.height = options.map_size;
  style.dpi = options.dpi;
  style.font = &font;
  return style;
}

render::FigureStyle chart_style(const PlotOptions& options, const std::vector<std::uint8_t>& font) {
  render::FigureStyle style = map_style(options, font);
  style.width = options.chart_width;
  style.height = options.chart_height;
  return style;
}

void write_png(const std::string& path, const render::Image& image) {
  const std::vector<std::uint8_t> png = render::encode_png(image);
  write_file_atomic(path, std::string(png.begin(), png.end()));
}

namespace {
// a CSV of numbers under a fixed header: one row of `columns` numbers per
// line; throws UserError "source:line: ..." naming what it expected
std::vector<std::vector<double>> parse_number_csv(const std::string& text, const std::string& source,
                                                  const std::string& header, const std::string& what) {
  const int columns = static_cast<int>(std::count(header.begin(), header.end(), ',')) + 1;
  std::vector<std::vector<double>> rows;
  std::size_t pos = 0;
  int line = 0;
  while (pos < text.size()) {
    const auto nl = text.find('\n', pos);
    std::string s = text.substr(pos, nl == std::string::npos ? std::string::npos : nl - pos);
    pos = nl == std::string::npos ? text.size() : nl + 1;
    ++line;
    if (!s.empty() && s.back() == '\r') s.pop_back();
    if (line == 1) {
      if (s != header) throw UserError(source + ":1: not " + what + ": expected the header '" + header + "'");
      continue;
    }
    if (s.empty()) continue;
    std::vector<double> v(static_cast<std::size_t>(columns));
    const char* p = s.c_str();
    for (int c = 0; c < columns; ++c) {
      char* end = nullptr;
      errno = 0;
      v[static_cast<std::size_t>(c)] = std::strtod(p, &end);
      const char want = c + 1 < columns ? ',' : '\0';
      if (end == p || errno == ERANGE || *end != want) {
        throw UserError(source + ":" + std::to_string(line) + ": column " + std::to_string(c + 1) +
                        " is not a number or the row does not have " + std::to_string(columns) + " columns");
      }
      p = end + (want ? 1 : 0);
    }
    rows.push_back(std::move(v));
  }
  if (line == 0) throw UserError(source + ": empty file, expected " + what);
  return rows;
}
}  // namespace

std::vector<LogRow> parse_log_csv(const std::string& text, const std::string& source) {
  std::vector<LogRow> rows;
  for (const std::vector<double>& v : parse_number_csv(text, source, kLogHeader, "a paddock log")) {
    LogRow r;
    r.t = v[0];
    r.x = v[1];
    r.y = v[2];
    r.yaw = v[3];
    r.vx = v[4];
    r.vy = v[5];
    r.yaw_rate = v[6];
    r.steer_cmd = v[7];
    r.steer = v[8];
    r.throttle = v[9];
    r.brake = v[10];
    r.v_ref = v[11];
    r.lateral_error = v[12];
    r.heading_error = v[13];
    r.s = v[14];
    r.lap = static_cast<int>(v[15]);
    r.as_state = static_cast<int>(v[16]);
    rows.push_back(r);
  }
  return rows;
}

std::vector<SlamSample> parse_slam_csv(const std::string& text, const std::string& source) {
  std::vector<SlamSample> rows;
  for (const std::vector<double>& v : parse_number_csv(text, source, kSlamCsvHeader, "a paddock slam.csv")) {
    SlamSample x;
    x.t = v[0];
    x.estimate = {v[1], v[2], v[3]};
    x.truth = {v[4], v[5], v[6]};
    x.error = v[7];
    x.sigma = v[8];
    rows.push_back(x);
  }
  return rows;
}

namespace {
// DIR/slam.csv (slam != ground_truth) -> the SLAM map over the true cones
// with the estimated and the true paths, and the position error over time
// with its 3-sigma bound
std::vector<std::string> plot_slam(const std::string& dir, const render::TrackMapData& track_map,
                                   const render::FigureStyle& map_style, const render::FigureStyle& chart_style) {
  const std::string path = dir + "/slam.csv";
  if (!std::filesystem::exists(path)) return {};
  const std::vector<SlamSample> series = parse_slam_csv(read_file(path), path);
  render::TrackMapData map = track_map;
  map.title = track_map.title.substr(0, track_map.title.find(':')) + ": SLAM map and paths";
  map.layers.clear();
  map.speed.clear();
  map.trajectory.clear();
  render::MapLayer truth{render::MapLayer::Kind::Polyline, "true path", {40, 40, 40, 255}, 1.0, render::Marker::Circle, {}, false};
  render::MapLayer estimate{render::MapLayer::Kind::Polyline, "estimated path", {214, 39, 40, 255}, 1.0, render::Marker::Circle, {}, false};
  for (const SlamSample& x : series) {
    truth.points.push_back(x.truth.position());
    estimate.points.push_back(x.estimate.position());
  }
  map.layers = {truth, estimate};

  // a point every 0.25 s: the chart draws a marker at each
  render::LineChartData chart;
  chart.title = map.title.substr(0, map.title.find(':')) + ": position error of the estimate";
  chart.x_label = "t [s]";
  chart.y_label = "error [m]";
  render::LineSeries err{"position error", {}, {}, {31, 119, 180, 255}, render::Marker::Circle};
  render::LineSeries bound{"3 sigma", {}, {}, {214, 39, 40, 255}, render::Marker::Cross};
  double next = -1e9;
  for (const SlamSample& x : series) {
    if (x.t < next) continue;
    next = x.t + 0.25;
    err.x.push_back(x.t);
    err.y.push_back(x.error);
    bound.x.push_back(x.t);
    bound.y.push_back(3.0 * x.sigma);
  }
  chart.series = {err, bound};
  const std::vector<std::string> paths = {dir + "/slam_map.png", dir + "/slam_error.png"};
  write_png(paths[0], render::draw_track_map(map, map_style).image);
  write_png(paths[1], render::draw_line_chart(chart, chart_style).image);
  return paths;
}
// one sample of DIR/limit_lines.csv's minimum-curvature line
struct LimitSample {
  Vec2 position;
  double speed = 0.0;
};

// the minimum-curvature line of DIR/limit_lines.csv (limit_lines_csv)
std::vector<LimitSample> read_limit_line(const std::string& path) {
  std::istringstream in(read_file(path));
  std::string line;
  int number = 0;
  std::vector<LimitSample> out;
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (number == 1) {
      if (line != "line,s,x,y,heading,curvature,speed")
        throw UserError(path + ":1: expected the header 'line,s,x,y,heading,curvature,speed'");
      continue;
    }
    if (line.empty()) continue;
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string item; std::getline(ss, item, ',');) f.push_back(item);
    double v[6];
    bool ok = f.size() == 7;
    for (std::size_t k = 1; ok && k < 7; ++k) {
      char* end = nullptr;
      v[k - 1] = std::strtod(f[k].c_str(), &end);
      ok = end != f[k].c_str() && *end == '\0' && std::isfinite(v[k - 1]);
    }
    if (!ok) throw UserError(path + ":" + std::to_string(number) + ": expected a line name and 6 finite numbers");
    if (f[0] == "min_curvature") out.push_back({{v[1], v[2]}, v[5]});
  }
  return out;
}

// DIR/limit.png: the best lap driven over the car's minimum-curvature line,
// coloured by how much slower than the line's QSS speed it went
std::vector<std::string> plot_limit(const std::string& dir, const render::TrackMapData& track_map,
                                    const std::vector<LogRow>& log, const SummaryLaps& laps,
                                    const render::FigureStyle& map_style) {
  const std::string path = dir + "/limit_lines.csv";
  if (!std::filesystem::exists(path) || laps.time.empty()) return {};
  const std::vector<LimitSample> line = read_limit_line(path);
  if (line.size() < 2) return {};
  // the best lap (a flying one when there are several)
  std::size_t best = laps.time.size() > 1 ? 1 : 0;
  for (std::size_t i = best; i < laps.time.size(); ++i)
    if (laps.time[i] < laps.time[best]) best = i;
  const double t0 = laps.start[best], t1 = t0 + laps.time[best];
  render::TrackMapData map = track_map;
  map.title = track_map.title.substr(0, track_map.title.find(':')) + ": lap " + std::to_string(best + 1) + " against the limit";
  map.layers.clear();
  map.estimated_cones.clear();
  map.trajectory.clear();
  map.speed.clear();
  render::MapLayer racing{render::MapLayer::Kind::Polyline, "minimum-curvature line", {150, 150, 150, 255}, 1.0, render::Marker::Circle, {}, true};
  for (const LimitSample& s : line) racing.points.push_back(s.position);
  map.layers.push_back(std::move(racing));
  for (const LogRow& r : log) {
    if (r.t < t0 || r.t > t1) continue;
    const Vec2 p{r.x, r.y};
    std::size_t near = 0;
    for (std::size_t k = 1; k < line.size(); ++k)
      if (squared_norm(line[k].position - p) < squared_norm(line[near].position - p)) near = k;
    map.trajectory.push_back(p);
    map.speed.push_back(line[near].speed - std::hypot(r.vx, r.vy));
  }
  map.trajectory_label = "lap " + std::to_string(best + 1) + " driven";
  map.speed_label = "QSS limit speed - driven speed [m/s]";
  const std::string out = dir + "/limit.png";
  write_png(out, render::draw_track_map(map, map_style).image);
  return {out};
}

}  // namespace

std::vector<std::string> plot_run(const std::string& dir, const PlotOptions& o) {
  // the run's files: its resolved scenario names the track
  const Scenario scenario = load_scenario(dir + "/scenario.ini");
  const world::TrackModel track = world::build_track(load_track_file(scenario.track_path));
  const std::vector<LogRow> log = parse_log_csv(read_file(dir + "/log.csv"), dir + "/log.csv");
  const SummaryLaps laps = read_summary(dir + "/summary.json");
  const std::vector<std::uint8_t> font = read_font(o);
  const std::string event = events::to_string(scenario.scenario.event);
  const render::FigureStyle map_style = runner::map_style(o, font);
  const render::FigureStyle chart_style = runner::chart_style(o, font);

  // the map: the track, and the path driven coloured by speed
  render::TrackMapData map;
  map.title = laps.scenario + ": " + event + " on " + track.name + (laps.finished ? ", total " + fmt(std::round(laps.total_time * 1000.0) / 1000.0) + " s" : ", DNF");
  map.cones = event_cones(track);
  map.left = track.left;
  map.right = track.right;
  map.closed = track.closed;
  map.gates = track.gates;
  map.start = start_pose(track, vehicle::footprint(scenario.vehicle).x_max);
  for (const LogRow& r : log) {
    map.trajectory.push_back({r.x, r.y});
    map.speed.push_back(std::hypot(r.vx, r.vy));
  }

  // the venue's barrier blocks ([venue]), outlined
  const std::vector<world::Block> blocks = world::venue_blocks(track, map.cones, scenario.venue);
  if (!blocks.empty()) {
    render::MapLayer layer;
    layer.kind = render::MapLayer::Kind::Segments;
    layer.label = "barrier";
    layer.color = {90, 90, 90, 255};
    layer.size = 1.0;
    for (const world::Block& b : blocks) {
      const std::vector<Vec2> c = world::block_corners(b);
      for (std::size_t k = 0; k < c.size(); ++k) {
        layer.points.push_back(c[k]);
        layer.points.push_back(c[(k + 1) % c.size()]);
      }
    }
    map.layers.push_back(std::move(layer));
  }
  add_plan_layers(dir + "/plan.json", map);

  // the controller data over the whole run, laps marked
  render::ControllerData ctl;
  ctl.title = laps.scenario + ": controller data";
  for (const LogRow& r : log) {
    ctl.t.push_back(r.t);
    ctl.steer_cmd.push_back(r.steer_cmd);
    ctl.steer.push_back(r.steer);
    ctl.v_ref.push_back(r.v_ref);
    ctl.v.push_back(r.vx);
    ctl.lateral_error.push_back(r.lateral_error);
    ctl.heading_error.push_back(r.heading_error);
  }
  ctl.lap_starts = laps.start;

  // the lap chart with the event's penalties
  const events::Rules rules = events::rules_for(scenario.scenario.event);
  render::LapChartData chart;
  chart.title = laps.scenario + ": lap times";
  chart.lap_times = laps.time;
  chart.timed = laps.timed;
  chart.doo = laps.doo;
  chart.oc = laps.oc;
  chart.doo_penalty = rules.doo_penalty;
  chart.oc_penalty = rules.oc_penalty;

  std::vector<std::string> paths = {dir + "/map.png", dir + "/controller.png", dir + "/laps.png"};
  write_png(paths[0], render::draw_track_map(map, map_style).image);
  write_png(paths[1], render::draw_controller_data(ctl, chart_style).image);
  write_png(paths[2], render::draw_lap_chart(chart, chart_style).image);
  for (const std::string& p : plot_perception(dir, map_style, chart_style)) paths.push_back(p);
  for (const std::string& p : plot_slam(dir, map, map_style, chart_style)) paths.push_back(p);
  for (const std::string& p : plot_limit(dir, map, log, laps, map_style)) paths.push_back(p);
  return paths;
}

}  // namespace paddock::runner
