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

// the margins the tests hold: the smallest distance (m) from any point of
// the raw centreline, the smoothed one and the trajectory to the true
// boundary lines (cone-to-cone segments). Measured with the default
// parameters (minimum over the tracks, raw / smoothed / trajectory):
//   ground truth, full lap:       1.36 / 1.10 / 1.08 (fss_2019 raw; fsg_2023)
//   the same with no colour:      1.36 / 1.10 / 1.08
//   cones within 20 m, open path: 1.26 / - / 1.25 (fsg_2024)
//   10 % missed, 5 % swapped, 0.1 m noise, laps that close (20 seeds):
//     fsg_2019 0.14 / - / 0.24 (where a missed inner cone lets the line cut
//     a corner that the true boundary still has), fsg_2023 0.79 / - / 0.57
constexpr double kLapMargin = 1.0;
constexpr double kPartialMargin = 1.0;
constexpr double kErrorMargin = 0.1;
constexpr unsigned kRobustSeeds = 20;

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
    EXPECT_GT(r.raw, kLapMargin) << name;
    EXPECT_GT(r.smoothed, kLapMargin) << name;
    EXPECT_GT(r.trajectory, kLapMargin) << name;
  }
}


TEST(PathPlannerTracks, RacingLineOnEveryCircuitIsFasterAndKeepsItsClearance) {
  // the racing line of each planned lap: inside the true boundaries by its
  // clearance (less 3 cm of spline between its points), winding the right
  // way, and faster round than the centreline with the same profile (by
  // 1-22 % on these tracks)
  PathPlannerParams p;
  p.reference.profile.limits = VelocityProfileParams::Ggv;
  for (const auto& name : kCircuits) {
    const TrackFile t = read_track(name);
    const Boundaries b = boundaries(t);
    PlanResult lap = plan_path(t.cones, start_pose(t), 0.0, p);
    ASSERT_TRUE(lap.ok() && lap.closed) << name << ": " << lap.reason;
    const double centre_time = lap_time(lap.trajectory);
    ASSERT_TRUE(plan_racing_line(lap, t.cones, p)) << name << ": " << lap.racing_fallback;
    EXPECT_TRUE(lap.trajectory.closed);
    const Fit fit = fit_in(b, trajectory_points(lap.trajectory));
    EXPECT_TRUE(fit.inside) << name;
    EXPECT_GT(fit.min_clearance, p.racing.clearance - 0.03) << name;
    EXPECT_TRUE(winds_right(trajectory_points(lap.trajectory), b)) << name;
    EXPECT_LT(lap_time(lap.trajectory), centre_time) << name;
    std::printf("%-18s centreline %.2f s, racing line %.2f s, clearance %.2f m\n", name.c_str(), centre_time,
                lap_time(lap.trajectory), fit.min_clearance);
  }
  // an open path is not a lap to race
  const TrackFile t = read_track("fsg_2023");
  PlanResult open = plan_path(t.cones, start_pose(t), 0.0, p, false);
  ASSERT_TRUE(open.ok());
  EXPECT_FALSE(plan_racing_line(open, t.cones, p));
  EXPECT_FALSE(open.racing_fallback.empty());
}

// ---- perception errors and LiDAR-only maps ------------------------------------------

// the map a good perception pipeline might build: each cone missed with
// probability `miss`, blue and yellow swapped with probability `flip`,
// Gaussian position noise of `noise` m on each axis; seeded
std::vector<Cone> perturb(const std::vector<Cone>& in, unsigned seed, double miss, double flip,
                          double noise) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<Cone> out;
  for (Cone c : in) {
    const bool missed = u(rng) < miss;
    const bool flipped = u(rng) < flip;
    const double dx = noise * n(rng), dy = noise * n(rng);
    if (missed) continue;
    if (flipped && c.color == ConeColor::Blue) c.color = ConeColor::Yellow;
    else if (flipped && c.color == ConeColor::Yellow) c.color = ConeColor::Blue;
    c.position += Vec2{dx, dy};
    out.push_back(c);
  }
  return out;
}

std::vector<Cone> without_colour(std::vector<Cone> cones) {
  for (Cone& c : cones) c.color = ConeColor::Unknown;
  return cones;
}

TEST(PathPlannerTracks, LidarOnlyFullLapOnEveryCircuit) {
  for (const auto& name : kCircuits) {
    const TrackFile t = read_track(name);
    const Boundaries b = boundaries(t);
    ASSERT_TRUE(b.ok) << name;
    const LapReport r = plan_lap(without_colour(t.cones), start_pose(t), b);
    std::printf("no colour %-18s closed %d raw %.2f smoothed %.2f traj %.2f\n", name.c_str(),
                r.closed, r.raw, r.smoothed, r.trajectory);
    EXPECT_TRUE(r.closed) << name << ": " << r.reason;
    EXPECT_TRUE(r.inside) << name;
    EXPECT_TRUE(r.winds) << name;
    EXPECT_GT(r.raw, kLapMargin) << name;
    EXPECT_GT(r.smoothed, kLapMargin) << name;
    EXPECT_GT(r.trajectory, kLapMargin) << name;
  }
}

// 20 seeded maps of each track with 10 % of the cones missed, 5 % of the
// blue and yellow ones swapped and 0.1 m of noise, with their colours and
// without. Measured: with colours 17 (FSG 2019) and 18 (FSG 2023) of 20
// close the lap inside the true boundaries, and the others stop safely
// inside at a gap of missed cones they cannot bridge (two or three in a
// row on one side); without colours 13 and 18 close, 5 stop inside, and 2
// of the 40 leave the track (FSG 2019 seeds 9 and 18) where missed cones
// opened a gap into a neighbouring part of the track. The bounds leave one
// lap of slack.
TEST(PathPlannerTracks, PerceptionErrorsOnFsg2019AndFsg2023) {
  for (const std::string name : {"fsg_2019", "fsg_2023"}) {
    const TrackFile t = read_track(name);
    const Boundaries b = boundaries(t);
    ASSERT_TRUE(b.ok);
    unsigned laps = 0, laps_no_colour = 0;
    for (unsigned seed = 1; seed <= kRobustSeeds; ++seed) {
      const auto cones = perturb(t.cones, seed, 0.10, 0.05, 0.1);
      for (bool colour : {true, false}) {
        const LapReport r = plan_lap(colour ? cones : without_colour(cones), start_pose(t), b);
        std::printf("errors%s %-9s seed %2u: closed %d inside %d raw %.2f traj %.2f %s\n",
                    colour ? "          " : " no colour", name.c_str(), seed, r.closed, r.inside,
                    r.raw, r.trajectory, r.reason.c_str());
        const bool lap = r.closed && r.inside && r.winds;
        (colour ? laps : laps_no_colour) += lap ? 1 : 0;
        if (lap) {
          EXPECT_GT(r.raw, kErrorMargin) << name << " seed " << seed << " colour " << colour;
          EXPECT_GT(r.trajectory, kErrorMargin) << name << " seed " << seed << " colour " << colour;
        }
        // with colours, a lap that does not close still stays on the track
        if (colour) {
          EXPECT_TRUE(r.inside) << name << " seed " << seed;
        }
      }
    }
    std::printf("%s: %u of %u laps close inside with colours, %u without\n", name.c_str(), laps,
                kRobustSeeds, laps_no_colour);
    EXPECT_GE(laps, name == "fsg_2019" ? 16u : 17u) << name;
    EXPECT_GE(laps_no_colour, name == "fsg_2019" ? 12u : 17u) << name;
  }
}

// the perturbed maps the search's defaults were checked on (centreline.h):
// 30 seeds on every circuit, 10 % of the cones missed, 5 % of the colours
// swapped, 0.1 m of noise, the whole map at once from the start pose. A lap
// fails when it does not close inside the true boundaries the right way
// round. Measured (2026-11-29): 29 of 420 fail with colours (21 outside the
// track, mostly on fss_2022_v1), 48 without (40 outside); with colours 40
// and 32 before an edge of one colour counted against a step either way.
// The bounds leave a few laps' room for a change that moves the search.
TEST(PathPlannerTracks, PerturbedMapsOnEveryCircuit) {
  unsigned fail[2] = {0, 0}, outside[2] = {0, 0};
  for (const auto& name : kCircuits) {
    const TrackFile t = read_track(name);
    const Boundaries b = boundaries(t);
    ASSERT_TRUE(b.ok) << name;
    for (unsigned seed = 101; seed <= 130; ++seed) {
      const auto cones = perturb(t.cones, seed, 0.10, 0.05, 0.1);
      for (int colour : {1, 0}) {
        const LapReport r = plan_lap(colour ? cones : without_colour(cones), start_pose(t), b);
        fail[colour] += r.closed && r.inside && r.winds ? 0 : 1;
        outside[colour] += r.inside ? 0 : 1;
      }
    }
  }
  std::printf("perturbed maps, 420 laps: with colours %u fail (%u outside), without %u (%u)\n", fail[1],
              outside[1], fail[0], outside[0]);
  EXPECT_LE(fail[1], 33u);
  EXPECT_LE(outside[1], 25u);
  EXPECT_LE(fail[0], 52u);
  EXPECT_LE(outside[0], 44u);
}

// ---- partial maps: what the car sees at the start -----------------------------------

// the cones within `seen` m of the start pose
std::vector<Cone> cones_near(const std::vector<Cone>& cones, const Pose2& start, double seen) {
  std::vector<Cone> near;
  for (const Cone& c : cones)
    if (distance(c.position, start.position()) <= seen) near.push_back(c);
  return near;
}

TEST(PathPlannerTracks, PartialMapGivesAnOpenPathThatEndsAtRest) {
  const double seen = 20.0;  // m around the start pose
  for (const auto& name : kCircuits) {
    const TrackFile t = read_track(name);
    const Boundaries b = boundaries(t);
    const Pose2 start = start_pose(t);
    const std::vector<Cone> near = cones_near(t.cones, start, seen);
    const double speed = 3.0;  // m/s
    const PlanResult plan = plan_path(near, start, speed);
    ASSERT_TRUE(plan.ok()) << name << ": " << plan.reason;
    EXPECT_FALSE(plan.closed) << name;
    const Trajectory& traj = plan.trajectory;
    ASSERT_FALSE(traj.empty());
    EXPECT_FALSE(traj.closed);
    // from the car, ahead of it, inside the track
    EXPECT_NEAR(traj.points.front().x, start.x, 1e-9) << name;
    EXPECT_NEAR(traj.points.front().y, start.y, 1e-9) << name;
    EXPECT_GT(dot(traj.points.back().position() - start.position(), start.heading()), 8.0) << name;
    const Fit raw = fit_in(b, plan.centreline), tr = fit_in(b, trajectory_points(traj));
    std::printf("partial %-18s points %2zu length %5.1f raw %.2f traj %.2f\n", name.c_str(),
                plan.centreline.size(), traj.length, raw.min_clearance, tr.min_clearance);
    EXPECT_TRUE(raw.inside && tr.inside) << name;
    EXPECT_GT(raw.min_clearance, kPartialMargin) << name;
    EXPECT_GT(tr.min_clearance, kPartialMargin) << name;
    // within the seen area, ending at rest; no faster than the car at first
    for (const auto& p : traj.points) EXPECT_LE(distance(p.position(), start.position()), seen + 1e-9) << name;
    EXPECT_EQ(traj.points.back().speed, 0.0) << name;
    EXPECT_LE(traj.points.front().speed, speed + 1e-9) << name;
  }
}

TEST(PathPlannerTracks, PartialMapRacesAsFarAsItIsKnown) {
  // line = min_curvature on an open path (an autocross, a first lap): the
  // racing line from the car to where the seen track ends, held on the
  // centreline at both ends, inside the track, bending less than the
  // centreline's open path over the same stretch
  const double seen = 20.0;  // m around the start pose
  PathPlannerParams racing;
  racing.line = PathPlannerParams::MinCurvature;
  racing.reference.profile.limits = VelocityProfileParams::Ggv;
  PathPlannerParams centre = racing;
  centre.line = PathPlannerParams::Centreline;
  for (const auto& name : kCircuits) {
    const TrackFile t = read_track(name);
    const Boundaries b = boundaries(t);
    const Pose2 start = start_pose(t);
    const std::vector<Cone> near = cones_near(t.cones, start, seen);
    const PlanResult plan = plan_path(near, start, 3.0, racing);
    const PlanResult base = plan_path(near, start, 3.0, centre);
    ASSERT_TRUE(plan.ok() && base.ok()) << name << ": " << plan.reason << base.reason;
    ASSERT_FALSE(plan.closed);
    ASSERT_FALSE(plan.racing_line.empty()) << name << ": " << plan.racing_fallback;
    EXPECT_TRUE(base.racing_line.empty());
    // pinned: from the car, to the centreline's end
    EXPECT_LT(distance(plan.racing_line.front(), start.position()), 1e-6) << name;
    EXPECT_LT(distance(plan.racing_line.back(), plan.smoothed.back()), 0.5) << name;
    EXPECT_NEAR(plan.trajectory.points.front().x, start.x, 1e-6) << name;
    EXPECT_NEAR(plan.trajectory.points.front().y, start.y, 1e-6) << name;
    EXPECT_EQ(plan.trajectory.points.back().speed, 0.0) << name;
    const Fit fit = fit_in(b, trajectory_points(plan.trajectory));
    EXPECT_TRUE(fit.inside) << name;
    EXPECT_GT(fit.min_clearance, kPartialMargin) << name;
    // it bends less: sum kappa^2 ds along the driven trajectories
    const auto bending = [](const Trajectory& tr) {
      double sum = 0.0;
      for (std::size_t i = 0; i + 1 < tr.points.size(); ++i) {
        const double k = tr.points[i].curvature;
        sum += k * k * (tr.points[i + 1].s - tr.points[i].s);
      }
      return sum;
    };
    const double b_racing = bending(plan.trajectory), b_centre = bending(base.trajectory);
    std::printf("partial racing %-18s sum kappa^2 ds %.4f against %.4f 1/m, %.2f s against %.2f s, clearance %.2f m\n",
                name.c_str(), b_racing, b_centre, lap_time(plan.trajectory), lap_time(base.trajectory),
                fit.min_clearance);
    // (where the stretch is all but straight, below 1e-3 1/m, a radius of
    // ~140 m over 20 m, leaving along the car's heading may bend it more)
    EXPECT_LT(b_racing, std::max(b_centre, 1e-3)) << name;
  }
}

// ---- abnormal maps: no trajectory and a reason ----------------------------------------

// the racing line's boundaries of a lap whose path cuts a corner: a
// rectangle 6 m wide with cones every 3 m, driven anticlockwise (blue
// inside, on the left), its path cutting the corner at (60, 0) by a chord
// from (56, 0) to (60, 4). The chord passes 1.4 m from the inner corner
// cone and 4.9 m from the outer cones either side of the outer corner,
// beyond the 3.5 m within which the path claims a cone; yet it crosses the
// rungs from the inner corner to them, so they bound it, on the right; and
// round that corner every cone bounds it on its own side. (The outer corner
// itself, 7.1 m off, is no rung's end: the two cones beside it close the
// triangulation there)
TEST(PathPlanner, ACutCornersOuterConesStillBoundItsRacingLine) {
  std::vector<Cone> cones;
  auto ring = [&](double x0, double y0, double x1, double y1, ConeColor c) {
    const std::vector<Vec2> corners{{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
    for (std::size_t k = 0; k < 4; ++k) {
      const Vec2 a = corners[k], b = corners[(k + 1) % 4];
      const int n = static_cast<int>(std::lround(distance(a, b) / 3.0));
      for (int i = 0; i < n; ++i) cones.push_back({a + (b - a) * (static_cast<double>(i) / n), c});
    }
  };
  ring(3.0, 3.0, 57.0, 27.0, ConeColor::Blue);      // inside
  ring(-3.0, -3.0, 63.0, 33.0, ConeColor::Yellow);  // outside
  PlanResult lap;
  lap.status = PlanStatus::Ok;
  lap.closed = true;
  lap.triangulation = triangulate(cones);
  ASSERT_TRUE(lap.triangulation.ok());
  // the centreline every 1 m, anticlockwise, the corner at (60, 0) cut
  const std::vector<Vec2> centre{{0.0, 0.0}, {60.0, 0.0}, {60.0, 30.0}, {0.0, 30.0}};
  for (std::size_t k = 0; k < 4; ++k) {
    const Vec2 a = centre[k], b = centre[(k + 1) % 4];
    for (int i = 0; i < static_cast<int>(distance(a, b)); ++i) {
      const Vec2 q = a + (b - a) * (i / distance(a, b));
      if (distance(q, {60.0, 0.0}) < 4.0 - 1e-9) continue;
      lap.smoothed.push_back(q);
    }
  }
  const std::vector<Vec2> outer{{60.0, -3.0}, {63.0, 0.0}};
  for (const Vec2& q : outer) ASSERT_GT(project(lap.smoothed, true, q).distance, 4.5);
  PathPlannerParams p;
  plan_racing_line(lap, cones, p);  // the boundaries come first, whatever the line does
  auto has = [](const std::vector<Vec2>& v, Vec2 q) {
    return std::any_of(v.begin(), v.end(), [&](Vec2 x) { return distance(x, q) < 1e-9; });
  };
  for (const Vec2& q : outer) EXPECT_TRUE(has(lap.right_boundary, q)) << q.x << " " << q.y;
  EXPECT_TRUE(has(lap.left_boundary, Vec2{57.0, 3.0}));
  // round the cut corner: the inner cones on the left, the outer on the right, each once
  auto near_cut = [](Vec2 q) { return q.x > 45.0 && q.y < 15.0; };
  auto inside = [](Vec2 q) { return q.x < 59.0 && q.y > 1.0; };
  std::size_t round_corner = 0;
  for (const Cone& c : cones) round_corner += near_cut(c.position) && distance(c.position, {63.0, -3.0}) > 1e-9;
  std::size_t bounding = 0;
  for (const Vec2& q : lap.left_boundary) {
    if (!near_cut(q)) continue;
    EXPECT_TRUE(inside(q)) << q.x << " " << q.y;
    ++bounding;
  }
  for (const Vec2& q : lap.right_boundary) {
    if (!near_cut(q)) continue;
    EXPECT_FALSE(inside(q)) << q.x << " " << q.y;
    ++bounding;
  }
  EXPECT_EQ(bounding, round_corner);
}

TEST(PathPlanner, AbnormalInputsGiveNoTrajectoryAndAReason) {
  const Pose2 start{0.0, 0.0, 0.0};
  auto expect_no_plan = [&](const std::vector<Cone>& cones, PlanStatus want, const char* what) {
    const PlanResult r = plan_path(cones, start, 0.0);
    EXPECT_EQ(r.status, want) << what << ": " << r.reason;
    EXPECT_FALSE(r.ok()) << what;
    EXPECT_FALSE(r.reason.empty()) << what;
    EXPECT_TRUE(r.trajectory.points.empty()) << what;
    std::printf("%-22s -> %s: %s\n", what, to_string(r.status), r.reason.c_str());
  };
  expect_no_plan({}, PlanStatus::NoTriangulation, "empty map");
  expect_no_plan({{{3.0, 1.5}, ConeColor::Blue}}, PlanStatus::NoTriangulation, "one cone");
  std::vector<Cone> line;
  for (int i = 0; i < 8; ++i) line.push_back({{3.0 * i, 1.5}, ConeColor::Blue});
  expect_no_plan(line, PlanStatus::NoTriangulation, "collinear cones");
  std::vector<Cone> doubled_one(4, Cone{{3.0, 1.5}, ConeColor::Yellow});
  expect_no_plan(doubled_one, PlanStatus::NoTriangulation, "one cone four times");
  const TrackFile t = read_track("fsg_2019");
  for (ConeColor c : {ConeColor::Blue, ConeColor::Yellow}) {
    std::vector<Cone> one;
    for (const Cone& k : t.cones)
      if (k.color == c) one.push_back(k);
    expect_no_plan(one, PlanStatus::NoCentreline, c == ConeColor::Blue ? "only blue cones" : "only yellow cones");
  }
  std::vector<Cone> all_blue = t.cones;
  for (Cone& k : all_blue) k.color = ConeColor::Blue;
  expect_no_plan(all_blue, PlanStatus::NoCentreline, "all cones blue");
  std::vector<Cone> nan(6, Cone{{std::nan(""), 0.0}, ConeColor::Blue});
  expect_no_plan(nan, PlanStatus::NoTriangulation, "NaN cones");

  // a bad pose or speed, bad parameters
  EXPECT_EQ(plan_path(t.cones, {std::nan(""), 0.0, 0.0}, 0.0).status, PlanStatus::BadInput);
  EXPECT_EQ(plan_path(t.cones, start, std::nan("")).status, PlanStatus::BadInput);
  PathPlannerParams bad;
  bad.smoothing.window = 2;
  const PlanResult r = plan_path(t.cones, start, 0.0, bad);
  EXPECT_EQ(r.status, PlanStatus::BadParams);
  EXPECT_FALSE(r.reason.empty());
  bad = {};
  bad.reference.ds = -1.0;
  EXPECT_EQ(plan_path(t.cones, start, 0.0, bad).status, PlanStatus::BadParams);
}

TEST(PathPlanner, DoubledMapPlansTheSameLap) {
  const TrackFile t = read_track("fsg_2021");
  std::vector<Cone> doubled = t.cones;
  for (const Cone& c : t.cones) doubled.push_back({c.position + Vec2{0.003, 0.002}, c.color});
  const PlanResult a = plan_path(t.cones, start_pose(t), 0.0);
  const PlanResult b = plan_path(doubled, start_pose(t), 0.0);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_TRUE(b.closed);
  EXPECT_EQ(b.triangulation.merged, t.cones.size());
  ASSERT_EQ(a.centreline.size(), b.centreline.size());
  for (std::size_t i = 0; i < a.centreline.size(); ++i) EXPECT_EQ(a.centreline[i], b.centreline[i]);
  EXPECT_NEAR(a.trajectory.length, b.trajectory.length, 1e-9);
}

TEST(PathPlanner, Deterministic) {
  const TrackFile t = read_track("fsg_2023");
  const PlanResult a = plan_path(t.cones, start_pose(t), 2.0);
  const PlanResult b = plan_path(t.cones, start_pose(t), 2.0);
  ASSERT_TRUE(a.ok());
  ASSERT_EQ(a.trajectory.points.size(), b.trajectory.points.size());
  for (std::size_t i = 0; i < a.trajectory.points.size(); ++i) {
    EXPECT_EQ(a.trajectory.points[i].x, b.trajectory.points[i].x);
    EXPECT_EQ(a.trajectory.points[i].y, b.trajectory.points[i].y);
    EXPECT_EQ(a.trajectory.points[i].speed, b.trajectory.points[i].speed);
  }
}

TEST(PathPlanner, ClosedLapHasAClosedProfile) {
  const TrackFile t = read_track("fsg_2023");
  const PlanResult plan = plan_path(t.cones, start_pose(t), 0.0);
  ASSERT_TRUE(plan.ok()) << plan.reason;
  ASSERT_TRUE(plan.closed);
  EXPECT_TRUE(plan.trajectory.closed);
  // the profile is periodic: nobody stops on a closed lap, and the speed at
  // the end of the lap leads into its start
  double v_min = kInf;
  for (const auto& p : plan.trajectory.points) v_min = std::min(v_min, p.speed);
  EXPECT_GT(v_min, 3.0);
  const double ds = plan.trajectory.length / static_cast<double>(plan.trajectory.points.size());
  const double dv2 = std::abs(plan.trajectory.points.back().speed * plan.trajectory.points.back().speed -
                              plan.trajectory.points.front().speed * plan.trajectory.points.front().speed);
  EXPECT_LE(dv2, 2.0 * 16.0 * ds);
  // the raw centreline is the search's lap, the smoothed one is shorter
  EXPECT_EQ(plan.centreline.size(), plan.search.points.size());
  EXPECT_LE(plan.smoothed.size(), plan.centreline.size());
  EXPECT_GT(plan.triangulation.edges.size(), 2 * t.cones.size());
}

// a lap the search closes before the car may take it for the circuit (the
// stack's `lap` false: a long-range map already shows the whole of it early
// in the first lap) is the open path along it from the car, once around,
// ending at rest short of the car; before, the planner gave only the lap and
// the stack held its last open path, which ended where the car then stopped
TEST(PathPlanner, ALapNotWantedYetIsAnOpenPathAlongIt) {
  const TrackFile t = read_track("fsg_2023");
  const Pose2 start = start_pose(t);
  const PlanResult lap = plan_path(t.cones, start, 5.0);
  ASSERT_TRUE(lap.ok() && lap.closed) << lap.reason;
  const PlanResult open = plan_path(t.cones, start, 5.0, PathPlannerParams{}, false);
  ASSERT_TRUE(open.ok()) << open.reason;
  EXPECT_FALSE(open.closed);
  EXPECT_FALSE(open.trajectory.closed);
  ASSERT_GE(open.centreline.size(), 3u);
  EXPECT_EQ(open.centreline.front(), start.position());
  // ahead of the car, and most of the lap long, ending short of the car at rest
  EXPECT_GT(dot(open.centreline[1] - start.position(), start.heading()), 0.0);
  EXPECT_GE(distance(open.centreline.back(), start.position()), PathPlannerParams{}.search.search_radius);
  EXPECT_GT(open.trajectory.length, 0.8 * lap.trajectory.length);
  EXPECT_LT(open.trajectory.length, lap.trajectory.length + 1.0);
  EXPECT_NEAR(open.trajectory.points.back().speed, 0.0, 1e-9);
  EXPECT_NEAR(open.trajectory.points.front().speed, 5.0, 0.5);
}

// ---- acceleration ----------------------------------------------------------------------

TEST(PathPlanner, AccelerationIsAStraightLineDownTheLane) {
  for (const std::string name : {"acceleration", "acceleration_amz_fssim"}) {
    const TrackFile t = read_track(name);
    const Pose2 start = start_pose(t);
    const PlanResult plan = plan_acceleration(t.cones, start, 0.0);
    ASSERT_TRUE(plan.ok()) << name << ": " << plan.reason;
    const Trajectory& traj = plan.trajectory;
    EXPECT_FALSE(traj.closed);
    // the lane is the x axis, to the last cone (150 m, FSSIM's 170 m)
    double x_end = 0.0;
    for (const Cone& c : t.cones) x_end = std::max(x_end, c.position.x);
    for (const auto& p : traj.points) {
      EXPECT_NEAR(p.y, 0.0, 0.05) << name << " s " << p.s;
      EXPECT_NEAR(p.heading, 0.0, 1e-3) << name;
      EXPECT_NEAR(p.curvature, 0.0, 1e-6) << name;
    }
    EXPECT_NEAR(traj.points.front().x, start.x, 0.05) << name;
    EXPECT_GT(traj.points.back().x, x_end - 10.0) << name;
    EXPECT_LE(traj.points.back().x, x_end) << name;
    EXPECT_EQ(traj.points.back().speed, 0.0);
    EXPECT_EQ(traj.points.front().speed, 0.0);
    // a given length: to the end of the braking zone
    const PlanResult fixed = plan_acceleration(t.cones, start, 0.0, {}, 120.0);
    ASSERT_TRUE(fixed.ok());
    EXPECT_NEAR(fixed.trajectory.length, 120.0, 1e-6);
  }
}

}  // namespace
}  // namespace paddock::planning
