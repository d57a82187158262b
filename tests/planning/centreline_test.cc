// the reward-based centreline search on synthetic tracks, its reward
// functions, and the abnormal inputs (the real circuits are in
// path_planner_test.cc).
#include "autonomy/planning/centreline.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <vector>

#include "autonomy/common/cone.h"
#include "autonomy/common/geometry.h"
#include "autonomy/planning/delaunay.h"

namespace paddock::planning {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// a straight track along +x: blue at y = +w/2, yellow at y = -w/2, a cone
// every `spacing` metres on each side, the yellow ones staggered by half
std::vector<Cone> straight_track(double length, double w = 3.5, double spacing = 4.0) {
  std::vector<Cone> cones;
  for (double x = 0.0; x <= length; x += spacing) {
    cones.push_back({{x, 0.5 * w}, ConeColor::Blue});
    cones.push_back({{x + 0.5 * spacing, -0.5 * w}, ConeColor::Yellow});
  }
  return cones;
}

// a ring track around the origin driven counter-clockwise: blue (left) on
// the inner circle, yellow on the outer one, about `spacing` metres apart
std::vector<Cone> ring_track(double r_centre, double w = 3.5, double spacing = 3.5) {
  std::vector<Cone> cones;
  for (double r : {r_centre - 0.5 * w, r_centre + 0.5 * w}) {
    const int n = static_cast<int>(std::round(2.0 * kPi * r / spacing));
    for (int i = 0; i < n; ++i) {
      const double a = 2.0 * kPi * i / n;
      cones.push_back({{r * std::cos(a), r * std::sin(a)},
                       r < r_centre ? ConeColor::Blue : ConeColor::Yellow});
    }
  }
  return cones;
}

std::vector<Cone> without_colour(std::vector<Cone> cones) {
  for (Cone& c : cones) c.color = ConeColor::Unknown;
  return cones;
}

CentrelineResult search(const std::vector<Cone>& cones, const Pose2& start,
                        const CentrelineParams& params = {}) {
  return search_centreline(triangulate(cones), cones, start, params);
}

// ---- the reward functions --------------------------------------------------------

TEST(Centreline, TrackWidthRewardIsThePapersFigure) {
  const CentrelineParams p;
  // 1 on the rules' range [3, 5] m
  for (double w : {3.0, 3.5, 4.0, 4.5, 5.0}) EXPECT_DOUBLE_EQ(track_width_reward(w, p), 1.0) << w;
  // a Gaussian fall-off below 3 m and above 5 m: 1.3 exp(-((w - edge)/0.4)^2 / 2) - 0.3
  const double one_sigma = 1.3 * std::exp(-0.5) - 0.3;
  EXPECT_NEAR(track_width_reward(2.6, p), one_sigma, 1e-12);
  // the figure's x - 5 above 5 m (the paper's equation repeats x - 3 there)
  EXPECT_NEAR(track_width_reward(5.4, p), one_sigma, 1e-12);
  // continuous at the range's edges, -0.3 far away
  EXPECT_NEAR(track_width_reward(3.0 - 1e-9, p), 1.0, 1e-6);
  EXPECT_NEAR(track_width_reward(5.0 + 1e-9, p), 1.0, 1e-6);
  EXPECT_NEAR(track_width_reward(0.0, p), -0.3, 1e-6);
  EXPECT_NEAR(track_width_reward(10.0, p), -0.3, 1e-6);
  // monotone on each side
  EXPECT_LT(track_width_reward(2.0, p), track_width_reward(2.5, p));
  EXPECT_GT(track_width_reward(5.5, p), track_width_reward(6.0, p));
}

TEST(Centreline, DefaultParametersAreValid) {
  EXPECT_EQ(params::validate(CentrelineParams{}), "");
  CentrelineParams p;
  p.weight_width = -1.0;
  EXPECT_EQ(params::validate(p), "weight_width must be in [0, 100] (got -1)");
  p = {};
  p.width_min = 6.0;  // above width_max
  EXPECT_EQ(params::validate(p), "width_max must be >= width_min");
  p = {};
  p.horizon_depth = 0;
  EXPECT_EQ(params::validate(p), "horizon_depth must be in [1, 8] (got 0)");
  p = {};
  p.min_step = p.search_radius + 1.0;
  EXPECT_EQ(params::validate(p), "min_step must be < search_radius");
  p = {};
  p.min_reward = kNaN;
  EXPECT_EQ(params::validate(p), "min_reward must be in [-10, 10] (got nan)");
  p = {};
  p.weight_colour = p.weight_width = p.weight_angle = p.weight_step = p.weight_prediction = p.weight_crossing = 0.0;
  EXPECT_EQ(params::validate(p),
            "weight_colour, weight_width, weight_angle, weight_step, weight_prediction and weight_crossing must not all be 0");
}

// ---- synthetic tracks ----------------------------------------------------------------

TEST(Centreline, StraightTrackGivesAnOpenPathDownTheMiddle) {
  const auto cones = straight_track(60.0);
  const CentrelineResult r = search(cones, {-1.0, 0.0, 0.0});
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_FALSE(r.closed);
  EXPECT_TRUE(r.stop == CentrelineStop::NoCandidate || r.stop == CentrelineStop::PoorContinuation)
      << to_string(r.stop);
  ASSERT_GE(r.points.size(), 20u);
  for (std::size_t i = 0; i < r.points.size(); ++i) {
    EXPECT_LT(std::abs(r.points[i].y), 0.6) << i;  // the rungs' midpoints zig-zag a little
    if (i > 0) {
      EXPECT_GT(r.points[i].x, r.points[i - 1].x) << i;
    }
  }
  // to the last rung (the cones end at x = 62)
  EXPECT_GT(r.points.back().x, 55.0);
  EXPECT_LE(r.points.back().x, 62.0);
  // the diagnostics: one step per point, each above the threshold, each
  // factor in its range
  ASSERT_EQ(r.steps.size(), r.points.size());
  const CentrelineParams p;
  std::set<std::size_t> edges;
  for (const CentrelineStep& s : r.steps) {
    EXPECT_GE(s.reward, p.min_reward);
    EXPECT_LE(s.reward, 1.0 + 1e-12);
    EXPECT_GE(s.horizon_reward, s.reward);
    EXPECT_GE(s.candidates, 1);
    for (double t : {s.terms.colour, s.terms.angle, s.terms.step, s.terms.prediction, s.terms.crossing}) {
      EXPECT_GE(t, -1.0);
      EXPECT_LE(t, 1.0);
    }
    EXPECT_GE(s.terms.width, -0.3);
    EXPECT_LE(s.terms.width, 1.0);
    // blue left, yellow right all the way
    EXPECT_GT(s.terms.colour, 0.5);
    // never the same edge twice
    EXPECT_TRUE(edges.insert(s.edge).second) << s.edge;
  }
}

TEST(Centreline, RingTrackClosesTheLoop) {
  for (bool colour : {true, false}) {
    const auto cones = colour ? ring_track(20.0) : without_colour(ring_track(20.0));
    // on the centreline at angle 0, heading counter-clockwise
    const CentrelineResult r = search(cones, {20.0, 0.0, kPi / 2});
    ASSERT_TRUE(r.ok()) << r.reason;
    EXPECT_TRUE(r.closed) << "colour " << colour << ": " << to_string(r.stop);
    EXPECT_EQ(r.stop, CentrelineStop::LoopClosed);
    EXPECT_NEAR(r.length, 2.0 * kPi * 20.0, 3.0);
    // every point between the boundaries, most near the middle
    for (const Vec2& q : r.points) {
      EXPECT_GT(norm(q), 18.25 + 0.6);
      EXPECT_LT(norm(q), 21.75 - 0.6);
    }
    // counter-clockwise all the way round: the angle only grows
    double turned = 0.0;
    for (std::size_t i = 0; i < r.points.size(); ++i) {
      const Vec2 a = r.points[i], b = r.points[(i + 1) % r.points.size()];
      const double d = std::atan2(cross(a, b), dot(a, b));
      EXPECT_GT(d, 0.0) << i;
      turned += d;
    }
    EXPECT_NEAR(turned, 2.0 * kPi, 1e-9);
  }
}

TEST(Centreline, StartingTheWrongWayRoundDoesNotFollowTheColours) {
  // clockwise on a ring whose blue cones are inside: blue on the right
  const auto cones = ring_track(20.0);
  const CentrelineResult wrong = search(cones, {20.0, 0.0, -kPi / 2});
  const CentrelineResult right = search(cones, {20.0, 0.0, kPi / 2});
  ASSERT_TRUE(right.ok());
  EXPECT_TRUE(right.closed);
  // the wrong way finds nothing it likes, or far less of it
  if (wrong.ok()) {
    double sum = 0.0;
    for (const auto& s : wrong.steps) sum += s.terms.colour;
    EXPECT_LT(sum / static_cast<double>(wrong.steps.size()), -0.5);
  }
}

TEST(Centreline, MaxPointsAndMaxLengthStopTheSearch) {
  const auto cones = straight_track(80.0);
  CentrelineParams p;
  p.max_points = 5;
  const CentrelineResult a = search(cones, {-1.0, 0.0, 0.0}, p);
  ASSERT_TRUE(a.ok());
  EXPECT_EQ(a.points.size(), 5u);
  EXPECT_EQ(a.stop, CentrelineStop::MaxPoints);
  p = {};
  p.max_length = 20.0;
  const CentrelineResult b = search(cones, {-1.0, 0.0, 0.0}, p);
  ASSERT_TRUE(b.ok());
  EXPECT_EQ(b.stop, CentrelineStop::MaxLength);
  EXPECT_GE(b.length, 20.0);
  EXPECT_LT(b.length, 20.0 + p.search_radius);
}

TEST(Centreline, ADeepHorizonDoesNotChangeTheEasyCase) {
  const auto cones = ring_track(15.0);
  for (int depth : {1, 2, 3, 4}) {
    CentrelineParams p;
    p.horizon_depth = depth;
    const CentrelineResult r = search(cones, {15.0, 0.0, kPi / 2}, p);
    ASSERT_TRUE(r.ok()) << depth;
    EXPECT_TRUE(r.closed) << depth;
  }
}

TEST(Centreline, Deterministic) {
  const auto cones = ring_track(25.0, 4.0, 4.5);
  const CentrelineResult a = search(cones, {25.0, 0.0, kPi / 2});
  const CentrelineResult b = search(cones, {25.0, 0.0, kPi / 2});
  ASSERT_EQ(a.points.size(), b.points.size());
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    EXPECT_EQ(a.points[i], b.points[i]);
    EXPECT_EQ(a.steps[i].edge, b.steps[i].edge);
  }
}

// a rung between two cones of one colour (a swapped cone, or a boundary
// edge as long as a rung) scores against the step whichever way it is
// crossed. The search once kept the two cones' vote as evidence for the
// edge's first cone's side, so a step that crossed it with that cone on its
// right scored the colour as a perfect rung's: which way that was depended
// on the cones' order in the map (an edge's first cone is the lower index),
// and on FSG 2019 the search stepped through a yellow boundary into the
// infield.
TEST(Centreline, ARungOfOneColourScoresAgainstWhicheverWayItsEdgeIsStored) {
  std::vector<Cone> cones = straight_track(60.0);
  // the blue cones at x = 20 and 24 taken for yellow ones: the four rungs
  // from them to the yellow cones at x = 18, 22 and 26 have one colour, too
  // many for a step to pass over (search_radius)
  for (Cone& c : cones)
    if (c.color == ConeColor::Blue && (std::abs(c.position.x - 20.0) < 1e-9 || std::abs(c.position.x - 24.0) < 1e-9))
      c.color = ConeColor::Yellow;
  const std::vector<Cone> reversed(cones.rbegin(), cones.rend());
  const CentrelineResult a = search(cones, {-1.0, 0.0, 0.0});
  const CentrelineResult b = search(reversed, {-1.0, 0.0, 0.0});
  ASSERT_TRUE(a.ok()) << a.reason;
  ASSERT_TRUE(b.ok()) << b.reason;
  // the same path and the same scores, whatever the cones' order
  ASSERT_EQ(a.points.size(), b.points.size());
  double lowest_other = 1.0;
  int one_colour = 0;
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    EXPECT_NEAR(distance(a.points[i], b.points[i]), 0.0, 1e-12) << i;
    EXPECT_NEAR(a.steps[i].terms.colour, b.steps[i].terms.colour, 1e-12) << i;
    // the one-colour rungs' midpoints: (19, 0) to (25, 0)
    const Vec2 q = a.points[i];
    if (std::abs(q.y) < 1e-9 && q.x > 18.5 && q.x < 25.5) {
      ++one_colour;
      EXPECT_LT(a.steps[i].terms.colour, 0.0) << i;
    } else if (q.x < 15.0 || q.x > 25.0) {
      lowest_other = std::min(lowest_other, a.steps[i].terms.colour);
    }
  }
  // the path still runs down the middle, over a swapped rung
  EXPECT_GE(one_colour, 1);
  EXPECT_GT(lowest_other, 0.5);
}

// ---- abnormal inputs: a status and a reason, never a crash ------------------------------

TEST(Centreline, AbnormalInputs) {
  const Pose2 start{0.0, 0.0, 0.0};
  auto expect_status = [&](const std::vector<Cone>& cones, CentrelineStatus want, const char* what) {
    const CentrelineResult r = search(cones, start);
    EXPECT_EQ(r.status, want) << what << ": " << r.reason;
    EXPECT_FALSE(r.reason.empty()) << what;
    EXPECT_TRUE(r.points.empty() || r.status == CentrelineStatus::Ok) << what;
    EXPECT_FALSE(r.closed) << what;
  };
  expect_status({}, CentrelineStatus::NoTriangulation, "empty map");
  expect_status({{{3.0, 1.5}, ConeColor::Blue}}, CentrelineStatus::NoTriangulation, "one cone");
  expect_status({{{3.0, 1.5}, ConeColor::Blue}, {{3.0, -1.5}, ConeColor::Yellow}},
                CentrelineStatus::NoTriangulation, "two cones");
  std::vector<Cone> line;
  for (int i = 0; i < 10; ++i) line.push_back({{2.0 * i, 1.5}, i % 2 ? ConeColor::Blue : ConeColor::Yellow});
  expect_status(line, CentrelineStatus::NoTriangulation, "collinear cones");
  // every cone of a track blue, or yellow, or orange: one boundary only
  for (ConeColor c : {ConeColor::Blue, ConeColor::Yellow, ConeColor::SmallOrange, ConeColor::BigOrange}) {
    auto one = straight_track(30.0);
    for (Cone& k : one) k.color = c;
    expect_status(one, CentrelineStatus::SingleColour, "one colour");
  }
  // the same cone many times over: one cone
  expect_status(std::vector<Cone>(5, Cone{{2.0, 1.0}, ConeColor::Blue}), CentrelineStatus::NoTriangulation,
                "one cone doubled");
  // all cones NaN
  expect_status(std::vector<Cone>(5, Cone{{kNaN, 1.0}, ConeColor::Blue}), CentrelineStatus::NoTriangulation,
                "NaN cones");
  // cones only behind the car: nothing ahead
  auto behind = straight_track(30.0);
  const CentrelineResult r = search(behind, {40.0, 0.0, 0.0});
  EXPECT_EQ(r.status, CentrelineStatus::NoPath);
  EXPECT_FALSE(r.reason.empty());
  // a NaN pose, bad parameters
  const auto track = straight_track(30.0);
  EXPECT_EQ(search(track, {kNaN, 0.0, 0.0}).status, CentrelineStatus::BadPose);
  EXPECT_EQ(search(track, {0.0, 0.0, std::numeric_limits<double>::infinity()}).status, CentrelineStatus::BadPose);
  CentrelineParams bad;
  bad.search_radius = -1.0;
  const CentrelineResult b = search(track, {-1.0, 0.0, 0.0}, bad);
  EXPECT_EQ(b.status, CentrelineStatus::BadParams);
  EXPECT_FALSE(b.reason.empty());
  // a triangulation of other cones
  EXPECT_EQ(search_centreline(triangulate(track), {}, {-1.0, 0.0, 0.0}).status,
            CentrelineStatus::NoTriangulation);
}

TEST(Centreline, DoubledConesChangeNothing) {
  const auto cones = ring_track(20.0);
  auto doubled = cones;
  for (const Cone& c : cones) doubled.push_back({c.position + Vec2{0.004, -0.003}, c.color});
  const CentrelineResult a = search(cones, {20.0, 0.0, kPi / 2});
  const CentrelineResult b = search(doubled, {20.0, 0.0, kPi / 2});
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_TRUE(b.closed);
  ASSERT_EQ(a.points.size(), b.points.size());
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    EXPECT_EQ(a.points[i], b.points[i]);
  }
}

TEST(Centreline, NonFiniteConesAreIgnored) {
  auto cones = ring_track(20.0);
  const CentrelineResult clean = search(cones, {20.0, 0.0, kPi / 2});
  cones.push_back({{kNaN, 3.0}, ConeColor::Blue});
  cones.insert(cones.begin() + 3, Cone{{1.0, std::numeric_limits<double>::infinity()}, ConeColor::Yellow});
  const CentrelineResult r = search(cones, {20.0, 0.0, kPi / 2});
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_TRUE(r.closed);
  EXPECT_EQ(r.points.size(), clean.points.size());
}

}  // namespace
}  // namespace paddock::planning
