#include "sim/runner/limit_report.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <future>
#include <map>
#include <mutex>
#include <optional>
#include <nlohmann/json.hpp>
#include <sstream>

#include "autonomy/common/format.h"
#include "autonomy/common/polyline.h"
#include "autonomy/planning/racing_line.h"
#include "autonomy/planning/reference.h"
#include "autonomy/planning/spline.h"
#include "sim/runner/files.h"
#include "sim/runner/ini.h"
#include "sim/runner/plots.h"
#include "sim/runner/schema.h"

namespace paddock::runner {

namespace {

// a line's figures from its trajectory
LimitLine summarise(std::string name, Trajectory traj, const world::TrackModel& track) {
  LimitLine l;
  l.name = std::move(name);
  l.lap_time = planning::lap_time(traj);
  l.v_min = 1e300;
  l.clearance_min = 1e300;
  for (const TrajectoryPoint& p : traj.points) {
    l.v_min = std::min(l.v_min, p.speed);
    l.v_max = std::max(l.v_max, p.speed);
    l.curvature_max = std::max(l.curvature_max, std::abs(p.curvature));
    l.clearance_min = std::min({l.clearance_min, polyline_distance(track.left, track.closed, p.position()),
                                polyline_distance(track.right, track.closed, p.position())});
  }
  l.trajectory = std::move(traj);
  return l;
}

}  // namespace

LimitLines limit_lines(const world::TrackModel& track, const planning::VelocityProfileParams& envelope,
                       double clearance) {
  if (track.kind != world::TrackKind::Circuit || !track.closed)
    throw UserError("limit: " + track.name + " is a " + std::string(world::track_kind_name(track.kind)) +
                    " track; only a circuit (trackdrive, autocross) has a lap");
  LimitLines out;
  out.clearance = clearance;
  planning::ReferenceParams ref;
  ref.profile = envelope;

  // the centreline, through the stack's own spline settings (3 m knots)
  const planning::ReferenceResult centre = planning::build_reference(track.centreline, true, ref);
  if (!centre.ok()) throw UserError("limit: " + track.name + ": centreline: " + centre.reason);
  out.centreline = summarise("centreline", centre.trajectory, track);

  // the minimum-curvature line, through every optimised point
  planning::RacingLineParams rp;
  rp.clearance = clearance;
  const planning::RacingLine line = planning::min_curvature_line(track.centreline, track.left, track.right, true, rp);
  if (!line.ok()) throw UserError("limit: " + track.name + ": " + line.reason);
  const planning::SplineFit fit = planning::fit_spline(line.points, true);
  if (!fit.ok()) throw UserError("limit: " + track.name + ": racing line spline: " + fit.reason);
  const planning::ReferenceResult racing = planning::reference_from_spline(fit.spline, ref);
  if (!racing.ok()) throw UserError("limit: " + track.name + ": racing line: " + racing.reason);
  out.min_curvature = summarise("min_curvature", racing.trajectory, track);
  out.cost_centreline = line.cost_reference;
  out.cost_min_curvature = line.cost;
  out.iterations = line.iterations;
  return out;
}

planning::VelocityProfileParams car_envelope(const vehicle::VehicleParams& car, GgvMeasurement* measured) {
  GgvMeasurement m = measure_ggv(car);
  planning::VelocityProfileParams e = ggv_envelope(m.rows, m.top_speed);
  if (measured) *measured = std::move(m);
  return e;
}

namespace {

// FNV-1a, 64 bits: a name for a cache entry (not a defence against anyone)
std::string hash_hex(const std::string& text) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (unsigned char c : text) h = (h ^ c) * 0x100000001b3ULL;
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

// The car's envelope kept on disk between runs: measuring it costs about a
// second of CPU (~1,000 s of the car driven at 1 kHz), a third of a one-lap
// run on one core, and every run of the same car in the same program
// measures the same numbers. An entry is the envelope's keys, each number
// as the shortest text that reads back to the same double, under this
// program's build ID (other code: another entry) and the car's fingerprint
// (its every parameter, exactly), hashed into the file's name and into the
// file: a result the program and the car alone determine, so a run that
// reads it gives what one that measures gives, bit for bit (tested). The
// folder keeps the 64 latest entries
struct EnvelopeCache {
  std::string path;      // "" when nothing can be kept (no cache folder or no build ID)
  std::string build;     // the program's build ID
  std::string car_hash;  // of the car's fingerprint

  explicit EnvelopeCache(const std::string& car_fingerprint) {
    const std::string dir = cache_dir();
    build = program_build_id();
    if (dir.empty() || build.empty()) return;
    car_hash = hash_hex("car\n" + car_fingerprint);
    path = dir + "/car-envelope-" + hash_hex(build + "\n" + car_fingerprint) + ".ini";
  }

  // the kept envelope, or none when there is none or it is not whole and
  // valid (a miss measures again and rewrites it)
  std::optional<planning::VelocityProfileParams> read() const {
    if (path.empty()) return std::nullopt;
    try {
      const std::vector<IniEntry> entries = parse_ini_text(read_file(path, 1 << 20), path, "");
      planning::VelocityProfileParams e;
      std::vector<Key> keys = profile_keys(e);
      bool build_ok = false, car_ok = false;
      std::size_t set = 0;
      for (const IniEntry& entry : entries) {
        if (entry.section == "cache") {
          if (entry.key == "build") build_ok = entry.value == build;
          if (entry.key == "car") car_ok = entry.value == car_hash;
          continue;
        }
        if (entry.section != "envelope") return std::nullopt;
        const auto k = std::find_if(keys.begin(), keys.end(), [&](const Key& key) { return key.name == entry.key; });
        if (k == keys.end()) return std::nullopt;
        k->set(entry);
        ++set;
      }
      if (!build_ok || !car_ok || set != keys.size() || !params::validate(e).empty()) return std::nullopt;
      return e;
    } catch (const std::exception&) {
      return std::nullopt;  // unreadable or malformed: measured again
    }
  }

  // keeps e (atomically); a folder that cannot be written keeps nothing
  void write(planning::VelocityProfileParams e) const {
    if (path.empty()) return;
    std::string text =
        "; the g-g-v envelope paddock measured for one car (the limit lap's), kept between runs; safe to delete\n"
        "[cache]\nbuild = " + build + "\ncar = " + car_hash + "\n[envelope]\n";
    for (const Key& k : profile_keys(e)) text += k.name + " = " + k.get() + "\n";
    try {
      write_file_atomic(path, text);
    } catch (const UserError&) {
      return;
    }
    prune();
  }

  // every build of the program keeps its own entries: the folder holds the
  // kKept most recently written, the others are removed
  static constexpr std::size_t kKept = 64;
  void prune() const {
    namespace fs = std::filesystem;
    std::error_code ec;
    std::vector<std::pair<fs::file_time_type, fs::path>> entries;
    for (const fs::directory_entry& f : fs::directory_iterator(fs::path(path).parent_path(), ec)) {
      const std::string name = f.path().filename().string();
      if (name.rfind("car-envelope-", 0) != 0 || f.path().extension() != ".ini") continue;
      const fs::file_time_type t = f.last_write_time(ec);
      if (!ec) entries.emplace_back(t, f.path());
    }
    if (entries.size() <= kKept) return;
    std::sort(entries.begin(), entries.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
    for (std::size_t i = kKept; i < entries.size(); ++i) {
      if (entries[i].second != fs::path(path)) fs::remove(entries[i].second, ec);
    }
  }
};

}  // namespace

planning::VelocityProfileParams kept_car_envelope(const vehicle::VehicleParams& car) {
  const EnvelopeCache cache(params::fingerprint(car));
  if (std::optional<planning::VelocityProfileParams> kept = cache.read()) return *kept;
  const planning::VelocityProfileParams e = car_envelope(car);
  cache.write(e);
  return e;
}

planning::VelocityProfileParams shared_car_envelope(const vehicle::VehicleParams& car) {
  static std::mutex mutex;
  static std::map<std::string, std::shared_future<planning::VelocityProfileParams>> measured;
  const std::string key = params::fingerprint(car);
  std::promise<planning::VelocityProfileParams> promise;
  std::shared_future<planning::VelocityProfileParams> future;
  {
    const std::lock_guard<std::mutex> lock(mutex);
    const auto it = measured.find(key);
    if (it != measured.end()) {
      future = it->second;
    } else {
      measured.emplace(key, promise.get_future().share());
    }
  }
  if (future.valid()) return future.get();  // measured, or being measured
  try {
    const planning::VelocityProfileParams e = kept_car_envelope(car);
    promise.set_value(e);
    return e;
  } catch (...) {
    promise.set_exception(std::current_exception());
    throw;
  }
}

LimitReport limit_report(const vehicle::VehicleParams& car, const world::TrackModel& track,
                         const std::string& scenario, double clearance) {
  LimitReport r;
  r.scenario = scenario;
  r.track = track.name;
  r.track_length = track.centreline_length;
  r.envelope = car_envelope(car, &r.ggv);
  r.steering_curvature = std::tan(car.steering_max) / (car.lf + car.lr);
  r.lines = limit_lines(track, r.envelope, clearance);
  return r;
}

namespace {

std::string line_row(const LimitLine& l, double steering_curvature) {
  char buf[240];
  std::snprintf(buf, sizeof buf, "    %-14s %7.1f m  %8.3f s  %6.2f  %6.2f  %6.2f m   %5.3f 1/m%s\n", l.name.c_str(),
                l.trajectory.length, l.lap_time, l.v_min, l.v_max, l.clearance_min, l.curvature_max,
                l.curvature_max > steering_curvature ? " (tighter than the steering lock)" : "");
  return buf;
}

}  // namespace

std::string limit_report_text(const LimitReport& r) {
  std::ostringstream o;
  o << "limit report: " << r.scenario << " (track " << r.track << ", centreline " << fixed(r.track_length, 1) << " m)\n";
  o << "  envelope    g-g-v measured on the car's model (closed-loop, 1 ms steps), top speed "
    << fixed(r.ggv.top_speed, 2) << " m/s\n";
  o << "    v [m/s]   lateral [m/s^2]   accel [m/s^2]   brake [m/s^2]\n";
  for (std::size_t i = 0; i < r.envelope.ggv_speed.size(); ++i) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "    %6.2f   %12.2f   %13.2f   %13.2f\n", r.envelope.ggv_speed[i],
                  r.envelope.ggv_lateral[i], r.envelope.ggv_accel[i], r.envelope.ggv_brake[i]);
    o << buf;
  }
  o << "  steering    lock curvature " << fixed(r.steering_curvature, 3) << " 1/m (radius "
    << fixed(1.0 / r.steering_curvature, 2) << " m)\n";
  o << "  QSS flying lap (forward-backward on the envelope, friction ellipse, no margin); clearance "
    << fixed(r.lines.clearance, 2) << " m from the boundary lines to the car's centre\n";
  o << "    line            length     lap       v min   v max   least clearance  max curvature\n";
  o << line_row(r.lines.centreline, r.steering_curvature);
  o << line_row(r.lines.min_curvature, r.steering_curvature);
  o << "  min curvature  sum kappa^2 ds " << fixed(r.lines.cost_centreline, 3) << " -> "
    << fixed(r.lines.cost_min_curvature, 3) << " 1/m in " << r.lines.iterations << " iterations; the limit lap is "
    << fixed(r.lines.min_curvature.lap_time, 3) << " s\n";
  return o.str();
}

std::string limit_report_json(const LimitReport& r) {
  using Json = nlohmann::ordered_json;
  const auto line = [](const LimitLine& l) {
    return Json{{"length", l.trajectory.length}, {"lap_time", l.lap_time},      {"v_min", l.v_min},
                {"v_max", l.v_max},              {"clearance_min", l.clearance_min}, {"curvature_max", l.curvature_max}};
  };
  Json j{{"scenario", r.scenario},
         {"track", r.track},
         {"track_length", r.track_length},
         {"clearance", r.lines.clearance},
         {"limit_lap_s", r.lines.min_curvature.lap_time},
         {"top_speed", r.ggv.top_speed},
         {"steering_curvature", r.steering_curvature},
         {"envelope",
          {{"speed", r.envelope.ggv_speed},
           {"lateral", r.envelope.ggv_lateral},
           {"accel", r.envelope.ggv_accel},
           {"brake", r.envelope.ggv_brake}}},
         {"centreline", line(r.lines.centreline)},
         {"min_curvature", line(r.lines.min_curvature)}};
  j["min_curvature"]["cost_reference"] = r.lines.cost_centreline;
  j["min_curvature"]["cost"] = r.lines.cost_min_curvature;
  j["min_curvature"]["iterations"] = r.lines.iterations;
  return j.dump(2) + "\n";
}

std::string limit_lines_csv(const LimitLines& lines) {
  std::ostringstream o;
  o << "line,s,x,y,heading,curvature,speed\n";
  char buf[200];
  for (const LimitLine* l : {&lines.centreline, &lines.min_curvature}) {
    for (const TrajectoryPoint& p : l->trajectory.points) {
      std::snprintf(buf, sizeof buf, "%s,%.3f,%.4f,%.4f,%.6f,%.6f,%.4f\n", l->name.c_str(), p.s, p.x, p.y, p.heading,
                    p.curvature, p.speed);
      o << buf;
    }
  }
  return o.str();
}

std::vector<std::string> write_limit_report(const LimitReport& r, const world::TrackModel& track, const std::string& dir,
                                            const PlotOptions& o) {
  const std::vector<std::uint8_t> font = read_font(o);
  const render::FigureStyle style = map_style(o, font);
  render::TrackMapData map;
  map.title = r.track + ": QSS limit " + fixed(r.lines.min_curvature.lap_time, 2) + " s on the minimum-curvature line";
  map.cones = track.cones;
  map.left = track.left;
  map.right = track.right;
  map.closed = track.closed;
  map.gates = track.gates;
  map.trajectory_label = "minimum-curvature line, QSS speed";
  render::MapLayer centre{render::MapLayer::Kind::Polyline, "centreline", {150, 150, 150, 255}, 0.8, render::Marker::Circle, {}, true};
  for (const TrajectoryPoint& p : r.lines.centreline.trajectory.points) centre.points.push_back(p.position());
  map.layers.push_back(std::move(centre));
  for (const TrajectoryPoint& p : r.lines.min_curvature.trajectory.points) {
    map.trajectory.push_back(p.position());
    map.speed.push_back(p.speed);
  }
  const std::vector<std::string> paths = {dir + "/limit_report.json", dir + "/limit_lines.csv", dir + "/limit.png"};
  write_file_atomic(paths[0], limit_report_json(r));
  write_file_atomic(paths[1], limit_lines_csv(r.lines));
  write_png(paths[2], render::draw_track_map(map, style).image);
  return paths;
}

}  // namespace paddock::runner
