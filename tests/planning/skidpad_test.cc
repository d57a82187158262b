// the skidpad: the rules' template against the real layout file, the
// figure-of-eight path, and the plan on the real cones moved by a known
// transform.
#include "autonomy/planning/skidpad.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "autonomy/common/cone.h"
#include "autonomy/common/geometry.h"

namespace paddock::planning {
namespace {

constexpr double kR = 9.125;  // the rules' centreline radius (m)

// a track file: `#` lines, a `tag,x,y` header, then one cone a row
std::vector<Cone> read_track(const std::string& name) {
  std::ifstream in(std::string(PADDOCK_SOURCE_DIR) + "/tracks/" + name);
  std::vector<Cone> cones;
  const std::map<std::string, ConeColor> tags = {{"blue", ConeColor::Blue},
                                                 {"yellow", ConeColor::Yellow},
                                                 {"orange", ConeColor::SmallOrange},
                                                 {"big_orange", ConeColor::BigOrange},
                                                 {"unknown", ConeColor::Unknown}};
  std::string line;
  bool header = false;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (!header) {
      header = true;  // tag,x,y
      continue;
    }
    std::stringstream ss(line);
    std::string tag, x, y;
    std::getline(ss, tag, ',');
    std::getline(ss, x, ',');
    std::getline(ss, y, ',');
    const auto it = tags.find(tag);
    if (it == tags.end()) continue;
    cones.push_back({{std::stod(x), std::stod(y)}, it->second});
  }
  return cones;
}

std::vector<Cone> moved(const std::vector<Cone>& cones, const Pose2& T) {
  std::vector<Cone> out = cones;
  for (Cone& c : out) c.position = T.transform(c.position);
  return out;
}

// distance of a template-frame point from the rules' path: the two
// centreline circles and the axis y = 0 of the lanes
double distance_to_ideal(Vec2 p) {
  const double right = std::abs(distance(p, {0.0, -kR}) - kR);
  const double left = std::abs(distance(p, {0.0, kR}) - kR);
  return std::min({right, left, std::abs(p.y)});
}

int count(const std::vector<Cone>& cones, ConeColor c) {
  return static_cast<int>(
      std::count_if(cones.begin(), cones.end(), [c](const Cone& k) { return k.color == c; }));
}

TEST(Skidpad, TemplateIsTheRulesLayoutOfTheTrackFile) {
  const std::vector<Cone> tmpl = skidpad_template_cones();
  const std::vector<Cone> file = read_track("skidpad.csv");
  ASSERT_EQ(file.size(), 73u);
  ASSERT_EQ(tmpl.size(), file.size());
  for (ConeColor c :
       {ConeColor::Blue, ConeColor::Yellow, ConeColor::SmallOrange, ConeColor::BigOrange})
    EXPECT_EQ(count(tmpl, c), count(file, c)) << cone_tag(c);
  EXPECT_EQ(count(tmpl, ConeColor::Blue), 29);
  EXPECT_EQ(count(tmpl, ConeColor::SmallOrange), 11);
  // each template cone has a cone of its colour in the file within 0.1 mm
  // (the file gives 4 decimals), and the other way round
  const auto nearest = [](const std::vector<Cone>& set, const Cone& c) {
    double best = std::numeric_limits<double>::infinity();
    for (const Cone& k : set)
      if (k.color == c.color) best = std::min(best, distance(k.position, c.position));
    return best;
  };
  for (const Cone& c : tmpl)
    EXPECT_LT(nearest(file, c), 1e-4) << c.position.x << ", " << c.position.y;
  for (const Cone& c : file)
    EXPECT_LT(nearest(tmpl, c), 1e-4) << c.position.x << ", " << c.position.y;
  // the rings: the lane between the cones' inner edges is 3 m
  const SkidpadGeometry g;
  EXPECT_DOUBLE_EQ(g.centreline_radius(), kR);
  EXPECT_NEAR(g.outer_cone_radius() - g.inner_cone_radius() - 2.0 * g.cone_offset, 3.0, 1e-12);
}

TEST(Skidpad, PathHasFourLapsOfTheCentrelineCircle) {
  const SkidpadPathParams params;
  const SkidpadPath path = skidpad_path(params);
  ASSERT_TRUE(path.ok()) << path.reason;
  const std::vector<Vec2>& p = path.points;
  ASSERT_GT(p.size(), 400u);
  // C0: consecutive points distinct and no farther apart than the spacing
  double length = 0.0;
  std::vector<double> s(p.size(), 0.0);
  for (std::size_t i = 1; i < p.size(); ++i) {
    const double d = distance(p[i - 1], p[i]);
    EXPECT_GT(d, 0.0) << i;
    EXPECT_LE(d, 1.02 * params.spacing) << i;
    length += d;
    s[i] = length;
  }
  // it starts on the entry lane's axis and stops short of the exit lane's end
  EXPECT_NEAR(p.front().x, -params.entry_length, 1e-12);
  EXPECT_NEAR(p.front().y, 0.0, 1e-12);
  EXPECT_NEAR(p.back().x, params.geometry.exit_end_x - params.exit_stop_distance, 1e-12);
  EXPECT_NEAR(p.back().y, 0.0, 1e-12);
  // four laps of 2 pi R within 1 %, each starting at the crossing; right
  // (clockwise) twice, then left (counter-clockwise) twice
  const double lap = 2.0 * kPi * kR;
  for (int k = 0; k < 4; ++k) {
    const std::size_t a = path.lap_start[k];
    const std::size_t b = k < 3 ? path.lap_start[k + 1] : path.exit_start;
    ASSERT_LT(a, b);
    EXPECT_NEAR(norm(p[a]), 0.0, 1e-12);
    EXPECT_NEAR(s[b] - s[a], lap, 0.01 * lap) << "lap " << k;
    double area2 = 0.0;  // twice the signed area swept
    const Vec2 centre{0.0, k < 2 ? -kR : kR};
    for (std::size_t i = a; i < b; ++i) {
      area2 += cross(p[i] - centre, p[i + 1] - centre);
      EXPECT_NEAR(distance(p[i], centre), kR, 1e-9);
    }
    if (k < 2) {
      EXPECT_LT(area2, 0.0) << "lap " << k << " is clockwise";
    } else {
      EXPECT_GT(area2, 0.0) << "lap " << k << " is counter-clockwise";
    }
    EXPECT_NEAR(std::abs(area2) / 2.0, kPi * kR * kR, 0.01 * kPi * kR * kR);
  }
  EXPECT_NEAR(norm(p[path.exit_start]), 0.0, 1e-12);
  // it passes the crossing 5 times: runs of points within 1 m of it
  int passes = 0;
  bool inside = false;
  for (const Vec2& q : p) {
    const bool near = norm(q) < 1.0;
    if (near && !inside) ++passes;
    inside = near;
  }
  EXPECT_EQ(passes, 5);
  std::printf("  %zu points, %.2f m; laps start at %zu %zu %zu %zu, exit at %zu\n", p.size(),
              length, path.lap_start[0], path.lap_start[1], path.lap_start[2], path.lap_start[3],
              path.exit_start);
}

TEST(Skidpad, PlanOnTheRealConesMovedByAKnownTransform) {
  const std::vector<Cone> file = read_track("skidpad.csv");
  ASSERT_EQ(file.size(), 73u);
  // the skidpad somewhere in a map; the guess as a start pose would give it,
  // 1.2 m and 0.15 rad off
  const Pose2 T_map_template{42.0, -17.0, 2.0};
  const std::vector<Cone> observed = moved(file, T_map_template);
  const Pose2 guess{T_map_template.x - 1.0, T_map_template.y + 0.7, T_map_template.yaw + 0.15};
  const SkidpadParams params;
  const SkidpadPlan plan = plan_skidpad(observed, guess, params);
  ASSERT_TRUE(plan.ok()) << plan.reason;
  const GicpResult& a = plan.alignment;
  std::printf(
      "  recovered T_map_template (%.5f, %.5f, %.6f) vs (%.1f, %.1f, %.1f); "
      "rmse %.2e m, %d inliers, %d iterations\n",
      a.transform.x, a.transform.y, a.transform.yaw, T_map_template.x, T_map_template.y,
      T_map_template.yaw, a.rmse, a.inliers, a.iterations);
  EXPECT_TRUE(a.converged);
  EXPECT_NEAR(plan.T_map_template.x, T_map_template.x, 0.05);
  EXPECT_NEAR(plan.T_map_template.y, T_map_template.y, 0.05);
  EXPECT_NEAR(plan.T_map_template.yaw, T_map_template.yaw, 0.5 * kPi / 180.0);
  // the real cones are the rules' layout to the file's 4 decimals
  EXPECT_LT(a.rmse, 0.05);
  EXPECT_EQ(a.inliers, 73);

  // the trajectory, back in the template frame, follows the rules' path
  const Trajectory& t = plan.trajectory;
  ASSERT_FALSE(t.empty());
  EXPECT_FALSE(t.closed);
  double worst = 0.0, worst_circle = 0.0;
  const SkidpadPath tmpl_path = skidpad_path(params.path);
  const double lap_begin_s = params.path.entry_length;  // arc length of the first crossing
  const double laps_end_s = lap_begin_s + 4.0 * 2.0 * kPi * kR;
  for (const TrajectoryPoint& tp : t.points) {
    const Vec2 q = plan.T_map_template.inverse_transform(tp.position());
    worst = std::max(worst, distance_to_ideal(q));
    // on the laps, the circle of the lap it is on
    if (tp.s > lap_begin_s + 1.0 && tp.s < laps_end_s - 1.0) {
      const int lap = static_cast<int>((tp.s - lap_begin_s) / (2.0 * kPi * kR));
      const Vec2 centre{0.0, lap < 2 ? -kR : kR};
      worst_circle = std::max(worst_circle, std::abs(distance(q, centre) - kR));
    }
  }
  std::printf(
      "  trajectory: %zu samples, %.2f m, worst distance from the rules' path %.3f m "
      "(from its lap's circle %.3f m), lap time %.2f s\n",
      t.points.size(), t.length, worst, worst_circle, lap_time(t));
  EXPECT_LT(worst, 0.3);
  EXPECT_LT(worst_circle, 0.3);
  // it ends at rest where the path ends, and goes no faster than the car may corner
  EXPECT_DOUBLE_EQ(t.points.back().speed, 0.0);
  const Vec2 end = plan.T_map_template.inverse_transform(t.points.back().position());
  EXPECT_NEAR(end.x, params.path.geometry.exit_end_x - params.path.exit_stop_distance, 0.05);
  const double v_circle = std::sqrt(params.reference.profile.ay_max * kR);
  for (const TrajectoryPoint& tp : t.points)
    if (tp.s > lap_begin_s + 3.0 && tp.s < laps_end_s - 3.0) {
      EXPECT_LT(tp.speed, 1.05 * v_circle);
    }
  // the path in the plan is the template path moved into the map
  ASSERT_EQ(plan.path.points.size(), tmpl_path.points.size());
  EXPECT_EQ(plan.path.lap_start, tmpl_path.lap_start);
  EXPECT_NEAR(distance(plan.path.points[10], plan.T_map_template.transform(tmpl_path.points[10])),
              0.0, 1e-9);
  EXPECT_NEAR(t.length, lap_begin_s + 4.0 * 2.0 * kPi * kR + 17.0, 0.5);
}

TEST(Skidpad, AlignedTemplateMatchesTheRealFile) {
  // the real file as the map, the template frame as the guess
  const std::vector<Cone> file = read_track("skidpad.csv");
  const SkidpadPlan plan = plan_skidpad(file, Pose2{}, SkidpadParams{});
  ASSERT_TRUE(plan.ok()) << plan.reason;
  std::printf("  skidpad.csv: T (%.2e, %.2e, %.2e), rmse %.2e m over %d cones\n",
              plan.T_map_template.x, plan.T_map_template.y, plan.T_map_template.yaw,
              plan.alignment.rmse, plan.alignment.inliers);
  EXPECT_LT(plan.alignment.rmse, 0.05);
  EXPECT_EQ(plan.alignment.inliers, 73);
  EXPECT_LT(std::hypot(plan.T_map_template.x, plan.T_map_template.y), 1e-3);
  EXPECT_LT(std::abs(plan.T_map_template.yaw), 1e-4);
}

TEST(Skidpad, AlignsTheFssimLayoutWithoutColours) {
  // another simulator's skidpad (its own lane cones and colours), as a
  // LiDAR-only map: every cone of unknown colour
  std::vector<Cone> fssim = read_track("skidpad_amz_fssim.csv");
  ASSERT_GT(fssim.size(), 70u);
  for (Cone& c : fssim) c.color = ConeColor::Unknown;
  const Pose2 T{-5.0, 12.0, -0.7};
  const SkidpadPlan plan =
      plan_skidpad(moved(fssim, T), Pose2{T.x + 0.5, T.y - 0.5, T.yaw - 0.1}, SkidpadParams{});
  ASSERT_TRUE(plan.ok()) << plan.reason;
  std::printf(
      "  skidpad_amz_fssim.csv: T (%.4f, %.4f, %.5f) vs (%.1f, %.1f, %.1f), rmse %.3f m "
      "over %d of %zu cones\n",
      plan.T_map_template.x, plan.T_map_template.y, plan.T_map_template.yaw, T.x, T.y, T.yaw,
      plan.alignment.rmse, plan.alignment.inliers, fssim.size());
  EXPECT_NEAR(plan.T_map_template.x, T.x, 0.05);
  EXPECT_NEAR(plan.T_map_template.y, T.y, 0.05);
  EXPECT_NEAR(plan.T_map_template.yaw, T.yaw, 0.5 * kPi / 180.0);
}

TEST(Skidpad, AbnormalInputsGiveAReason) {
  const SkidpadParams params;
  const auto expect_fail = [](const SkidpadPlan& plan, const char* what) {
    EXPECT_FALSE(plan.ok()) << what;
    EXPECT_TRUE(plan.trajectory.empty()) << what;
    std::printf("  %-24s -> %s\n", what, plan.reason.c_str());
  };
  expect_fail(plan_skidpad({}, Pose2{}, params), "no cones");
  expect_fail(plan_skidpad({{{1.0, 2.0}, ConeColor::Blue}}, Pose2{}, params), "one cone");
  std::vector<Cone> line;
  for (int i = 0; i < 10; ++i) line.push_back({{-15.0 + 3.0 * i, 1.65}, ConeColor::SmallOrange});
  expect_fail(plan_skidpad(line, Pose2{}, params), "collinear cones");
  std::vector<Cone> file = read_track("skidpad.csv");
  std::vector<Cone> with_nan = file;
  with_nan[7].position.x = std::numeric_limits<double>::quiet_NaN();
  expect_fail(plan_skidpad(with_nan, Pose2{}, params), "NaN cone");
  expect_fail(plan_skidpad(file, Pose2{std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0}, params),
              "NaN guess");
  expect_fail(plan_skidpad(moved(file, Pose2{500.0, 0.0, 0.0}), Pose2{}, params),
              "cones far from the guess");
  // a few cones only: too few to trust
  std::vector<Cone> few(file.begin(), file.begin() + 5);
  expect_fail(plan_skidpad(few, Pose2{}, params), "five cones");
  SkidpadParams bad = params;
  bad.path.spacing = 0.0;
  expect_fail(plan_skidpad(file, Pose2{}, bad), "zero spacing");
  bad = params;
  bad.path.geometry.inner_diameter = 30.0;
  expect_fail(plan_skidpad(file, Pose2{}, bad), "inner > outer diameter");
  bad = params;
  bad.path.exit_stop_distance = 25.0;
  expect_fail(plan_skidpad(file, Pose2{}, bad), "stop beyond the exit");
  bad = params;
  bad.gicp.max_iterations = 0;
  expect_fail(plan_skidpad(file, Pose2{}, bad), "no iterations");
  bad = params;
  bad.reference.ds = -1.0;
  expect_fail(plan_skidpad(file, Pose2{}, bad), "negative ds");
  // an alignment that converges but is not good enough
  bad = params;
  bad.min_inliers = 100;
  expect_fail(plan_skidpad(file, Pose2{}, bad), "min_inliers 100");
  bad = params;
  bad.max_rmse = 0.01;
  expect_fail(plan_skidpad(read_track("skidpad_amz_fssim.csv"), Pose2{}, bad),
              "FSSIM, max_rmse 1 cm");
  // and the pieces alone
  SkidpadPathParams pp;
  pp.spacing = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(skidpad_path(pp).ok());
  EXPECT_TRUE(skidpad_path(pp).points.empty());
  SkidpadGeometry g;
  g.cones_per_ring = 2;
  EXPECT_TRUE(skidpad_template_cones(g).empty());
}

}  // namespace
}  // namespace paddock::planning
