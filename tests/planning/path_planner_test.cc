// one planning cycle on the real cone maps in tracks/: a full lap on every
// circuit stays inside the boundaries with a margin, with ground-truth cones,
// with perception errors and with no colour at all; partial maps give an
// open path that ends at rest; abnormal maps give a reason, not a crash.
#include "autonomy/planning/path_planner.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "autonomy/common/cone.h"
#include "autonomy/common/geometry.h"
#include "autonomy/common/polyline.h"

namespace paddock::planning {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// ---- a tiny reader of tracks/*.csv -------------------------------------------

struct TrackFile {
  std::vector<Cone> cones;
  std::optional<Pose2> start;  // "# start X Y YAW"
};

TrackFile read_track(const std::string& name) {
  TrackFile t;
  std::ifstream in(std::string(PADDOCK_SOURCE_DIR) + "/tracks/" + name + ".csv");
  EXPECT_TRUE(in.good()) << name;
  const std::map<std::string, ConeColor> tags{{"blue", ConeColor::Blue},
                                              {"yellow", ConeColor::Yellow},
                                              {"orange", ConeColor::SmallOrange},
                                              {"big_orange", ConeColor::BigOrange},
                                              {"unknown", ConeColor::Unknown}};
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("# start", 0) == 0) {
      std::istringstream s(line.substr(7));
      Pose2 p;
      s >> p.x >> p.y >> p.yaw;
      t.start = p;
      continue;
    }
    if (line.empty() || line[0] == '#' || line.rfind("tag,", 0) == 0) continue;
    std::istringstream s(line);
    std::string tag, x, y;
    std::getline(s, tag, ',');
    std::getline(s, x, ',');
    std::getline(s, y, ',');
    const auto it = tags.find(tag);
    EXPECT_NE(it, tags.end()) << name << ": " << line;
    if (it == tags.end()) continue;
    t.cones.push_back({{std::stod(x), std::stod(y)}, it->second});
  }
  return t;
}

std::vector<Vec2> positions(const std::vector<Cone>& cones, ConeColor c) {
  std::vector<Vec2> out;
  for (const Cone& k : cones) {
    if (k.color != c) continue;
    // a doubled cone counts once (some files have pairs ~0.1-0.5 m apart)
    bool dup = false;
    for (const Vec2& q : out) dup = dup || distance(q, k.position) < 0.6;
    if (!dup) out.push_back(k.position);
  }
  return out;
}

// the start pose: the file's, or (fsds_training has none) halfway between the
// first blue cone and its nearest yellow cone, facing so that blue is left
Pose2 start_pose(const TrackFile& t) {
  if (t.start) return *t.start;
  const auto blue = positions(t.cones, ConeColor::Blue);
  const auto yellow = positions(t.cones, ConeColor::Yellow);
  const Vec2 b = blue.front();
  Vec2 y = yellow.front();
  for (const Vec2& q : yellow)
    if (distance(q, b) < distance(y, b)) y = q;
  const Vec2 d = b - y;  // points left of the heading
  return {0.5 * (b.x + y.x), 0.5 * (b.y + y.y), angle_of({d.y, -d.x})};
}

// ---- the boundaries, ordered independently of the planner ----------------------

bool segments_cross(Vec2 a, Vec2 b, Vec2 c, Vec2 d) {
  const double d1 = cross(b - a, c - a), d2 = cross(b - a, d - a);
  const double d3 = cross(d - c, a - c), d4 = cross(d - c, b - c);
  return ((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0));
}

bool simple_polygon(const std::vector<Vec2>& p) {
  const std::size_t n = p.size();
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // neighbours through the wrap
      if (segments_cross(p[i], p[(i + 1) % n], p[j], p[(j + 1) % n])) return false;
    }
  return true;
}

// one colour's cones in driving order: from the cone nearest the start, each
// time the next cone that is near and keeps the direction (distance weighted
// by the turn), never back by more than 100 degrees
std::vector<Vec2> order_boundary(const std::vector<Vec2>& cones, const Pose2& start) {
  std::vector<Vec2> out;
  if (cones.empty()) return out;
  std::vector<bool> used(cones.size(), false);
  std::size_t cur = 0;
  for (std::size_t i = 1; i < cones.size(); ++i)
    if (distance(cones[i], start.position()) < distance(cones[cur], start.position())) cur = i;
  Vec2 dir = start.heading();
  used[cur] = true;
  out.push_back(cones[cur]);
  while (true) {
    double best_cost = kInf;
    std::size_t best = cones.size();
    for (std::size_t i = 0; i < cones.size(); ++i) {
      if (used[i]) continue;
      const Vec2 d = cones[i] - cones[cur];
      const double l = norm(d);
      if (l > 15.0) continue;
      const double turn = std::abs(std::atan2(cross(dir, d), dot(dir, d)));
      if (turn > 1.75) continue;
      const double cost = l * (1.0 + 1.5 * turn);
      if (cost < best_cost) {
        best_cost = cost;
        best = i;
      }
    }
    if (best == cones.size()) break;
    dir = (cones[best] - cones[cur]) / distance(cones[best], cones[cur]);
    cur = best;
    used[cur] = true;
    out.push_back(cones[cur]);
  }
  return out;
}

struct Boundaries {
  std::vector<Vec2> blue, yellow;  // closed polygons in driving order
  bool ok = false;
  std::string why;

  bool inside(Vec2 q) const { return polygon_contains(blue, q) != polygon_contains(yellow, q); }
  double clearance(Vec2 q) const {
    return std::min(project(blue, true, q).distance, project(yellow, true, q).distance);
  }
};

Boundaries boundaries(const TrackFile& t) {
  Boundaries b;
  const Pose2 s = start_pose(t);
  const auto blue = positions(t.cones, ConeColor::Blue);
  const auto yellow = positions(t.cones, ConeColor::Yellow);
  b.blue = order_boundary(blue, s);
  b.yellow = order_boundary(yellow, s);
  // the ordering must use every cone, return to its start and not cross itself
  for (const auto* side : {&b.blue, &b.yellow}) {
    const std::size_t n = side == &b.blue ? blue.size() : yellow.size();
    if (side->size() != n) b.why += "ordered " + std::to_string(side->size()) + " of " + std::to_string(n) + "; ";
    else if (distance(side->front(), side->back()) > 15.0) b.why += "not closed; ";
    else if (!simple_polygon(*side)) b.why += "self-crossing; ";
  }
  b.ok = b.why.empty();
  return b;
}

// how a path sits in the track: inside everywhere, and its smallest clearance
struct Fit {
  bool inside = true;
  double min_clearance = kInf;
  std::size_t worst = 0;
};
Fit fit_in(const Boundaries& b, const std::vector<Vec2>& path) {
  Fit f;
  for (std::size_t i = 0; i < path.size(); ++i) {
    f.inside = f.inside && b.inside(path[i]);
    const double c = b.clearance(path[i]);
    if (c < f.min_clearance) {
      f.min_clearance = c;
      f.worst = i;
    }
  }
  return f;
}

std::vector<Vec2> trajectory_points(const Trajectory& t) {
  std::vector<Vec2> out;
  for (const auto& p : t.points) out.push_back(p.position());
  return out;
}

// a closed path goes round the right way: blue on its left, so it encloses
// every blue cone and no yellow one when counter-clockwise, and vice versa
bool winds_right(const std::vector<Vec2>& path, const Boundaries& b) {
  const bool ccw = polygon_area(path) > 0.0;
  for (const Vec2& q : b.blue)
    if (polygon_contains(path, q) != ccw) return false;
  for (const Vec2& q : b.yellow)
    if (polygon_contains(path, q) == ccw) return false;
  return true;
}

const std::vector<std::string> kCircuits{
    "fsg_2019",      "fsg_2021",      "fsg_2023",         "fsg_2024",        "fse_2022",
    "fse_2022_test", "fse_2023",      "fse_2024",         "fss_2019",        "fss_2022_v1",
    "fsg_amz_fssim", "fsi_amz_fssim", "eufs_small_track", "fsds_training"};

// ---- the boundaries themselves ----------------------------------------------------

TEST(PathPlannerTracks, TestBoundariesAreSound) {
  for (const auto& name : kCircuits) {
    const TrackFile t = read_track(name);
    const Boundaries b = boundaries(t);
    EXPECT_TRUE(b.ok) << name << ": " << b.why;
    EXPECT_TRUE(b.inside(start_pose(t).position())) << name;
  }
}

// ---- full laps on every circuit ---------------------------------------------------

struct LapReport {
  bool closed = false;
  bool inside = false;
  bool winds = false;
  double raw = 0.0, smoothed = 0.0, trajectory = 0.0;  // minimum clearances (m)
  std::size_t points = 0;
  double length = 0.0;
  std::string reason;
};

LapReport plan_lap(const std::vector<Cone>& cones, const Pose2& start, const Boundaries& b,
                   const PathPlannerParams& params = {}) {
  LapReport r;
  const PlanResult plan = plan_path(cones, start, 0.0, params);
  r.reason = plan.reason + " / " + to_string(plan.search.stop);
  r.points = plan.search.points.size();
  r.length = plan.search.length;
  if (!plan.ok()) return r;
  r.closed = plan.closed && plan.trajectory.closed;
  const auto traj = trajectory_points(plan.trajectory);
  const Fit raw = fit_in(b, plan.centreline), sm = fit_in(b, plan.smoothed), tr = fit_in(b, traj);
  r.inside = raw.inside && sm.inside && tr.inside;
  r.raw = raw.min_clearance;
  r.smoothed = sm.min_clearance;
  r.trajectory = tr.min_clearance;
  r.winds = r.closed && winds_right(traj, b);
  return r;
}

TEST(PathPlannerTracks, FullLapOnEveryCircuitStaysInside) {
  std::printf("%-18s %6s %7s %6s %8s %8s %8s\n", "track", "points", "length", "closed", "raw",
              "smoothed", "traj");
  for (const auto& name : kCircuits) {
    const TrackFile t = read_track(name);
    const Boundaries b = boundaries(t);
    ASSERT_TRUE(b.ok) << name;
    const LapReport r = plan_lap(t.cones, start_pose(t), b);
    std::printf("%-18s %6zu %7.1f %6d %8.2f %8.2f %8.2f %s\n", name.c_str(), r.points, r.length,
                r.closed, r.raw, r.smoothed, r.trajectory, r.reason.c_str());
    EXPECT_TRUE(r.closed) << name << ": " << r.reason;
    EXPECT_TRUE(r.inside) << name;
    EXPECT_TRUE(r.winds) << name;
  }
}

}  // namespace
}  // namespace paddock::planning
