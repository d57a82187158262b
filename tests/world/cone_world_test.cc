// the cone world checked against physics (Coulomb sliding, impact momentum,
// the tipping impulse) and against ground truth (which cone the car touches).
#include "sim/world/cone_world.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <vector>

namespace paddock::world {
namespace {

constexpr double kDt = 1e-3;  // s, the closed loop's physics step

// an FS car: rear axle 0.5 m ahead of the tail, nose 2.4 m ahead of it, 1.4 m wide
const Footprint kCar{0.5, 2.4, 0.7};

// a car moving along a straight line at constant speed
struct Straight {
  Vec2 start;
  double yaw = 0.0;
  double speed = 0.0;  // m/s
  Pose2 at(double t) const {
    const Vec2 p = start + unit_from_angle(yaw) * (speed * t);
    return {p.x, p.y, yaw};
  }
};

// drive from t = 0 to t_end with the car pose given per time (velocity from
// the pose difference), calling `each` after every step
void drive(ConeWorld& w, const std::function<Pose2(double)>& pose, double t0, double t_end,
           const std::function<void(int)>& each = nullptr) {
  const int n = static_cast<int>(std::lround((t_end - t0) / kDt));
  for (int k = 1; k <= n; ++k) {
    const double t = t0 + k * kDt;
    const Pose2 p = pose(t), q = pose(t - kDt);
    w.step(p, (p.x - q.x) / kDt, (p.y - q.y) / kDt, wrap_angle(p.yaw - q.yaw) / kDt, kDt);
    if (each) each(k);
  }
}

// a lane: cones every 5 m for 100 m, 3 m apart, blue on the left, yellow right
std::vector<Cone> lane() {
  std::vector<Cone> cones;
  for (int k = 0; k <= 20; ++k) {
    cones.push_back({{5.0 * k, 1.5}, ConeColor::Blue});
    cones.push_back({{5.0 * k, -1.5}, ConeColor::Yellow});
  }
  return cones;
}

TEST(ConeWorld, DefaultKnockImpulsesAreTheTippingImpulses) {
  const ConeWorldParams p;
  EXPECT_EQ(params::validate(p), "");
  // a hit 0.10 m above the ground (FS front wing end plate / nose)
  EXPECT_NEAR(tipping_impulse(0.228, 0.325, 0.9, 0.10), 1.5431, 1e-3);
  EXPECT_NEAR(tipping_impulse(0.285, 0.505, 1.9, 0.10), 4.7108, 1e-3);
  EXPECT_NEAR(p.small_cone.knock_impulse, tipping_impulse(0.228, 0.325, 0.9, 0.10), 0.05);
  EXPECT_NEAR(p.big_cone.knock_impulse, tipping_impulse(0.285, 0.505, 1.9, 0.10), 0.05);
  // a higher hit needs less: J ~ 1 / hit_height
  EXPECT_NEAR(tipping_impulse(0.228, 0.325, 0.9, 0.20), 0.5 * tipping_impulse(0.228, 0.325, 0.9, 0.10), 1e-12);
}

TEST(ConeWorld, RejectsBadParamsAndFootprint) {
  ConeWorldParams bad;
  bad.ground_friction = -0.1;
  EXPECT_EQ(params::validate(bad), "ground_friction must be in [0, 5] (got -0.1)");
  EXPECT_THROW(ConeWorld(lane(), bad, kCar), std::invalid_argument);
  bad = ConeWorldParams{};
  bad.big_cone.knock_impulse = 0.0;
  EXPECT_EQ(params::validate(bad), "big_cone.knock_impulse must be in (0, 1000] N s (got 0)");
  bad = ConeWorldParams{};
  bad.world_margin = 0.01;  // inside wake_margin
  EXPECT_EQ(params::validate(bad), "world_margin must be >= wake_margin");
  EXPECT_THROW(ConeWorld(lane(), bad, kCar), std::invalid_argument);
  EXPECT_THROW(ConeWorld(lane(), ConeWorldParams{}, Footprint{0.0, 0.0, 0.7}), std::invalid_argument);
  std::vector<Cone> nan_cone{{{std::nan(""), 0.0}, ConeColor::Blue}};
  EXPECT_THROW(ConeWorld(nan_cone, ConeWorldParams{}, kCar), std::invalid_argument);
}

TEST(ConeWorld, EmptyWorldAndBadStepsAreHarmless) {
  ConeWorld w({}, ConeWorldParams{}, kCar);
  drive(w, [](double t) { return Straight{{0, 0}, 0.3, 10.0}.at(t); }, 0.0, 0.5);
  EXPECT_EQ(w.doo_count(), 0);
  EXPECT_EQ(w.stats().steps, 500);
  w.step({std::nan(""), 0.0, 0.0}, 0.0, 0.0, 0.0, kDt);
  w.step({0.0, 0.0, 0.0}, 0.0, 0.0, 0.0, 0.0);
  EXPECT_EQ(w.stats().rejected_steps, 2);
  EXPECT_EQ(w.stats().steps, 500);
  EXPECT_EQ(w.time_ns(), 500'000'000);
}

TEST(ConeWorld, DrivingDownALaneTouchesNothing) {
  const std::vector<Cone> cones = lane();
  for (const bool skip : {true, false}) {
    ConeWorldParams p;
    p.skip_idle_steps = skip;
    ConeWorld w(cones, p, kCar);
    drive(w, [](double t) { return Straight{{-10.0, 0.0}, 0.0, 15.0}.at(t); }, 0.0, 8.0);
    EXPECT_EQ(w.doo_count(), 0);
    EXPECT_TRUE(w.doo_cones().empty());
    for (int i = 0; i < w.cone_count(); ++i) {
      // bit for bit
      EXPECT_EQ(w.cone_position(i).x, cones[i].position.x);
      EXPECT_EQ(w.cone_position(i).y, cones[i].position.y);
      EXPECT_FALSE(w.cone_knocked(i));
      EXPECT_EQ(w.doo_step(i), -1);
    }
    EXPECT_EQ(w.stats().steps, 8000);
    // the clearance is 1.5 - 0.7 - 0.114 = 0.686 m > wake_margin: Box2D never runs
    if (skip) {
      EXPECT_EQ(w.stats().box2d_steps, 0);
      EXPECT_LT(w.stats().proximity_queries, 8000 / 10);
    } else {
      EXPECT_EQ(w.stats().box2d_steps, 8000);
    }
  }
}

TEST(ConeWorld, GrazingWithinTheMarginStepsBox2DButMovesNothing) {
  // the car's left side passes 1 cm from the cone edges: inside wake_margin
  const std::vector<Cone> cones = lane();
  ConeWorld w(cones, ConeWorldParams{}, kCar);
  const double y = 1.5 - 0.114 - 0.01 - 0.7;
  drive(w, [y](double t) { return Straight{{-10.0, y}, 0.0, 15.0}.at(t); }, 0.0, 8.0);
  EXPECT_GT(w.stats().box2d_steps, 0);
  EXPECT_EQ(w.doo_count(), 0);
  for (int i = 0; i < w.cone_count(); ++i) {
    EXPECT_EQ(w.cone_position(i).x, cones[i].position.x);
    EXPECT_EQ(w.cone_position(i).y, cones[i].position.y);
  }
}

TEST(ConeWorld, DrivingThroughAConeAt10MsKnocksItForward) {
  // the cone's edge is at x = 10 - 0.114; the nose (2.4 m ahead of the base)
  // reaches it when the base is at 7.486 m, i.e. at t = 0.7486 s
  const ConeWorldParams p;
  ConeWorld w({{{10.0, 0.2}, ConeColor::Yellow}, {{10.0, 5.0}, ConeColor::Blue}}, p, kCar);
  const Straight car{{0.0, 0.0}, 0.0, 10.0};
  std::vector<Vec2> track;
  drive(w, [&car](double t) { return car.at(t); }, 0.0, 1.5, [&](int) { track.push_back(w.cone_position(0)); });
  ASSERT_EQ(w.doo_count(), 1);
  EXPECT_EQ(w.doo_cones(), std::vector<int>{0});
  EXPECT_TRUE(w.cone_knocked(0));
  EXPECT_EQ(w.doo_events()[0].cause, DooCause::Knocked);
  EXPECT_NEAR(static_cast<double>(w.doo_step(0)), 749.0, 2.0);
  EXPECT_EQ(w.doo_time_ns(0), w.doo_step(0) * 1'000'000);
  // pushed forward, in the car's direction
  const Vec2 d = w.cone_position(0) - Vec2{10.0, 0.2};
  EXPECT_GT(d.x, 3.0);
  EXPECT_LT(std::abs(d.y), 0.05 * d.x);
  // momentum: the flat nose hits it head-on, so the cone leaves at (1 + e) v =
  // 12 m/s, less the ground friction deceleration mu g while it slides
  const int k0 = static_cast<int>(w.doo_step(0));  // step index (1-based) of the impact
  const double v_fly = (track[k0 + 20 - 1].x - track[k0 + 10 - 1].x) / (10 * kDt);
  EXPECT_NEAR(v_fly, (1.0 + p.car_cone_restitution) * 10.0 - p.ground_friction * kGravity * 0.015, 0.02);
  // the other cone was never touched
  EXPECT_EQ(w.cone_position(1).x, 10.0);
  EXPECT_EQ(w.cone_position(1).y, 5.0);
}

TEST(ConeWorld, KnockThresholdSeparatesSlowAndFastHits) {
  // a head-on hit gives the impulse m (1 + e) v (inelastic below 1 m/s), so the
  // knock threshold 1.5 N s is crossed at v = 1.5 / (0.9 * 1.2) = 1.39 m/s
  for (const double v : {0.8, 1.2, 1.35, 1.43, 1.6, 3.0}) {
    ConeWorld w({{{5.0, 0.0}, ConeColor::Blue}}, ConeWorldParams{}, kCar);
    // drive up to the cone at v and stop 0.2 m after first touching it
    const double x_touch = 5.0 - 0.114 - 2.4, t_stop = (x_touch + 0.2) / v;
    drive(w, [&](double t) { return Pose2{v * std::min(t, t_stop), 0.0, 0.0}; }, 0.0, t_stop + 2.0);
    EXPECT_EQ(w.cone_knocked(0), v > 1.39) << "v = " << v;
  }
}

TEST(ConeWorld, SlowPushCountsByDisplacementOnly) {
  // the nose starts 5 cm short of the cone and pushes it at 0.3 m/s
  const double r = 0.114, x_cone = 3.0;
  ConeWorld w({{{x_cone, 0.0}, ConeColor::Blue}}, ConeWorldParams{}, kCar);
  const double x0 = x_cone - r - 0.05 - kCar.front;
  int became = -1;
  double before = 0.0, after = 0.0, last = 0.0;
  drive(w, [x0](double t) { return Pose2{x0 + 0.3 * t, 0.0, 0.0}; }, 0.0, 2.0, [&](int k) {
    const double disp = norm(w.cone_position(0) - Vec2{x_cone, 0.0});
    // DOO exactly when the displacement first exceeds the base radius
    EXPECT_EQ(w.cone_doo(0), disp > r || became >= 0) << "step " << k << " displacement " << disp;
    if (became < 0 && w.cone_doo(0)) {
      became = k;
      before = last;
      after = disp;
    }
    last = disp;
  });
  ASSERT_EQ(w.doo_count(), 1);
  EXPECT_FALSE(w.cone_knocked(0));
  EXPECT_EQ(w.doo_events()[0].cause, DooCause::Displaced);
  EXPECT_EQ(w.doo_step(0), became);
  EXPECT_LE(before, r);
  EXPECT_GT(after, r);
  // pushed by 0.3 m/s * 2 s - 0.05 m of approach = 0.55 m, along +x
  const Vec2 d = w.cone_position(0) - Vec2{x_cone, 0.0};
  EXPECT_NEAR(d.x, 0.55, 0.02);
  EXPECT_GT(d.x, 0.5);
  EXPECT_NEAR(d.y, 0.0, 1e-3);
}

TEST(ConeWorld, SlidingConeStopsAtTheCoulombDistance) {
  // Coulomb friction decelerates a sliding cone at mu g whatever its mass:
  // it stops after v^2 / (2 mu g)
  const ConeWorldParams p;
  for (const ConeColor color : {ConeColor::Blue, ConeColor::BigOrange}) {
    for (const double v0 : {1.0, 3.0, 6.0}) {
      ConeWorld w({{{20.0, -4.0}, color}, {{-20.0, 30.0}, ConeColor::Yellow}}, p, kCar);
      const Vec2 dir = unit_from_angle(0.5);
      w.kick_cone(0, dir * v0);
      // the car stands still far away
      drive(w, [](double) { return Pose2{-50.0, 0.0, 0.0}; }, 0.0, 3.0);
      const Vec2 d = w.cone_position(0) - Vec2{20.0, -4.0};
      const double expected = v0 * v0 / (2.0 * p.ground_friction * kGravity);
      EXPECT_NEAR(norm(d), expected, 0.10 * expected) << "v0 " << v0;
      EXPECT_NEAR(norm(d), expected, 0.01 * expected + v0 * kDt) << "v0 " << v0;
      EXPECT_NEAR(angle_of(d), 0.5, 1e-3);
      EXPECT_FALSE(w.cone_knocked(0));
      EXPECT_EQ(w.cone_doo(0), norm(d) > 0.5 * (color == ConeColor::BigOrange ? 0.285 : 0.228));
      // once it has stopped it sleeps and Box2D stops running
      const double t_stop = v0 / (p.ground_friction * kGravity);
      EXPECT_LT(w.stats().box2d_steps, std::lround((t_stop + 0.05) / kDt));
    }
  }
}

TEST(ConeWorld, EachConeCountsOnceAfterManyHits) {
  ConeWorld w({{{10.0, 0.0}, ConeColor::Blue}, {{60.0, 8.0}, ConeColor::Yellow}}, ConeWorldParams{}, kCar);
  // forward at 10 m/s for 3 s, back at 10 m/s for 2 s, forward again for 3 s:
  // the cone is hit again and again
  const auto x_of = [](double t) {
    if (t < 3.0) return 10.0 * t;
    if (t < 5.0) return 30.0 - 10.0 * (t - 3.0);
    return 10.0 + 10.0 * (t - 5.0);
  };
  int hits = 0;
  double last_x = 10.0, last_v = 0.0;
  drive(w, [&](double t) { return Pose2{x_of(t), 0.0, 0.0}; }, 0.0, 8.0, [&](int) {
    const double x = w.cone_position(0).x, v = (x - last_x) / kDt;
    if (v - last_v > 1.0) ++hits;  // a jump of the cone's speed: a hit
    last_x = x;
    last_v = v;
  });
  EXPECT_GE(hits, 3);
  EXPECT_EQ(w.doo_count(), 1);
  EXPECT_EQ(w.doo_cones(), std::vector<int>{0});
  EXPECT_EQ(w.doo_events().size(), 1u);
  EXPECT_NEAR(static_cast<double>(w.doo_step(0)), 749.0, 2.0);
  EXPECT_FALSE(w.cone_doo(1));
}

// a slalom the car hits part of: several cones, cone-cone contacts, sleeping
std::vector<Cone> slalom() {
  std::vector<Cone> cones;
  for (int k = 0; k < 30; ++k) {
    cones.push_back({{8.0 + 4.0 * k, (k % 2 ? 0.9 : -0.9)}, k % 2 ? ConeColor::Blue : ConeColor::Yellow});
    cones.push_back({{8.3 + 4.0 * k, (k % 2 ? 1.2 : -1.2)}, ConeColor::SmallOrange});
  }
  cones.push_back({{70.0, 0.0}, ConeColor::BigOrange});
  return cones;
}
Pose2 weave(double t) {
  const double x = 12.0 * t, a = 1.1, k = 2.0 * kPi / 13.0;
  return {x, a * std::sin(k * x), std::atan(a * k * std::cos(k * x))};
}

TEST(ConeWorld, DeterministicBitForBit) {
  const std::vector<Cone> cones = slalom();
  ConeWorld a(cones, ConeWorldParams{}, kCar), b(cones, ConeWorldParams{}, kCar);
  // interleaved: no hidden shared state between worlds
  for (int k = 1; k <= 12000; ++k) {
    const double t = k * kDt;
    const Pose2 p = weave(t), q = weave(t - kDt);
    a.step(p, (p.x - q.x) / kDt, (p.y - q.y) / kDt, (p.yaw - q.yaw) / kDt, kDt);
    b.step(p, (p.x - q.x) / kDt, (p.y - q.y) / kDt, (p.yaw - q.yaw) / kDt, kDt);
  }
  ASSERT_GE(a.doo_count(), 3);  // the weave does hit cones
  EXPECT_LT(a.doo_count(), static_cast<int>(cones.size()));
  EXPECT_EQ(a.doo_cones(), b.doo_cones());
  ASSERT_EQ(a.doo_events().size(), b.doo_events().size());
  for (size_t e = 0; e < a.doo_events().size(); ++e) {
    EXPECT_EQ(a.doo_events()[e].step, b.doo_events()[e].step);
    EXPECT_EQ(a.doo_events()[e].cause, b.doo_events()[e].cause);
  }
  for (int i = 0; i < a.cone_count(); ++i) {
    EXPECT_EQ(a.cone_position(i).x, b.cone_position(i).x);
    EXPECT_EQ(a.cone_position(i).y, b.cone_position(i).y);
    EXPECT_EQ(a.cone_knocked(i), b.cone_knocked(i));
  }
  EXPECT_EQ(a.stats().box2d_steps, b.stats().box2d_steps);
  // and a third run, moved into place, after the others
  ConeWorld c = ConeWorld(cones, ConeWorldParams{}, kCar);
  drive(c, weave, 0.0, 12.0);
  EXPECT_EQ(c.doo_cones(), a.doo_cones());
  for (int i = 0; i < a.cone_count(); ++i) EXPECT_EQ(c.cone_position(i).x, a.cone_position(i).x);
}

// down the lane centre at 15 m/s, swerving left between x = 25 m and 45 m
// into the blue cones, then on down the lane and 40 m beyond it
Pose2 swerve(double t) {
  const double x = -10.0 + 15.0 * t;
  if (x < 25.0 || x > 45.0) return {x, 0.0, 0.0};
  const double k = kPi / 10.0, a = 0.6;
  return {x, a * (1.0 - std::cos(k * (x - 25.0))), std::atan(a * k * std::sin(k * (x - 25.0)))};
}

TEST(ConeWorld, SkippingIdleStepsGivesTheSameOutcome) {
  const std::vector<Cone> cones = lane();
  ConeWorldParams always;
  always.skip_idle_steps = false;
  ConeWorld a(cones, ConeWorldParams{}, kCar), b(cones, always, kCar);
  drive(a, swerve, 0.0, 10.0);
  drive(b, swerve, 0.0, 10.0);
  ASSERT_GE(a.doo_count(), 1);
  EXPECT_EQ(b.stats().box2d_steps, 10000);
  // Box2D runs while the car is at the cones and the hit cones slide, not after
  EXPECT_LT(a.stats().box2d_steps, 5000);
  EXPECT_EQ(a.doo_cones(), b.doo_cones());
  for (size_t e = 0; e < a.doo_events().size(); ++e) EXPECT_EQ(a.doo_events()[e].step, b.doo_events()[e].step);
  for (int i = 0; i < a.cone_count(); ++i) {
    EXPECT_NEAR(a.cone_position(i).x, b.cone_position(i).x, 1e-3) << i;
    EXPECT_NEAR(a.cone_position(i).y, b.cone_position(i).y, 1e-3) << i;
    EXPECT_EQ(a.cone_knocked(i), b.cone_knocked(i)) << i;
  }
  // at the end every cone rests again and has left the Box2D world
  EXPECT_EQ(a.bodies_in_world(), 0);
  EXPECT_EQ(b.bodies_in_world(), a.cone_count());
}

TEST(ConeWorld, AFlyingConeKnocksAnother) {
  // the car hits cone 0 at 10 m/s and stops 0.3 m later; cone 0 flies at
  // 12 m/s into cone 1, 3 m ahead and far from the car: equal masses, e = 0.2,
  // so cone 1 takes (1 + e) / 2 of the closing speed, far above the knock
  // threshold. Cone 1 only becomes a Box2D body when cone 0 comes near it.
  const std::vector<Cone> cones{{{10.0, 0.0}, ConeColor::Blue}, {{13.0, 0.05}, ConeColor::Blue}};
  const double x_touch = 10.0 - 0.114 - kCar.front, t_stop = (x_touch + 0.3) / 10.0;
  const auto car = [&](double t) { return Pose2{10.0 * std::min(t, t_stop), 0.0, 0.0}; };
  ConeWorldParams always;
  always.skip_idle_steps = false;
  ConeWorld a(cones, ConeWorldParams{}, kCar), b(cones, always, kCar);
  int most_bodies = 0, bodies_in_flight = -1;
  drive(a, car, 0.0, 5.0, [&](int k) {
    most_bodies = std::max(most_bodies, a.bodies_in_world());
    if (k == 800) bodies_in_flight = a.bodies_in_world();  // cone 0 flying, 2 m short of cone 1
  });
  drive(b, car, 0.0, 5.0);
  ASSERT_EQ(a.doo_cones(), (std::vector<int>{0, 1}));
  EXPECT_EQ(a.doo_cones(), b.doo_cones());
  EXPECT_TRUE(a.cone_knocked(1));
  EXPECT_EQ(a.doo_events()[1].cause, DooCause::Knocked);
  // cone 1 is hit 3 m - 2 r later than cone 0, after about 0.23 s of flight
  const double dt_hit = static_cast<double>(a.doo_step(1) - a.doo_step(0)) * kDt;
  EXPECT_NEAR(dt_hit, 0.23, 0.03);
  EXPECT_GT(a.cone_position(1).x - 13.0, 1.0);
  EXPECT_NEAR(a.cone_position(1).x, b.cone_position(1).x, 1e-3);
  EXPECT_NEAR(a.cone_position(0).x, b.cone_position(0).x, 1e-3);
  EXPECT_EQ(bodies_in_flight, 1);
  EXPECT_EQ(most_bodies, 2);
}

TEST(ConeWorld, AConeTheWindMovesIsNotTheCarsDoo) {
  // the wind slides cone 0 by 0.6 m across the lane: it stops at the Coulomb
  // distance (the speed it is given is sqrt(2 mu g d)), and neither it nor the
  // cone it is blown into counts; the car stands far away
  const ConeWorldParams p;
  for (const bool topple : {false, true}) {
    ConeWorld w({{{20.0, 1.5}, ConeColor::Blue}, {{20.0, 0.9}, ConeColor::Blue}, {{40.0, 1.5}, ConeColor::Blue}}, p, kCar);
    w.disturb_cone(0, {0.0, -0.6}, topple);
    w.disturb_cone(2, {0.5, 0.0}, false);
    EXPECT_EQ(w.cone_knocked(0), topple);
    drive(w, [](double) { return Pose2{-50.0, 0.0, 0.0}; }, 0.0, 3.0);
    EXPECT_EQ(w.doo_count(), 0) << "topple " << topple;
    // cone 2 slid freely: the Coulomb distance, in the wind's direction
    EXPECT_NEAR(w.cone_position(2).x - 40.0, 0.5, 0.02);
    EXPECT_NEAR(w.cone_position(2).y, 1.5, 1e-3);
    // cone 0 was blown into cone 1 (0.6 m away, edges 0.372 m apart) and pushed it
    EXPECT_LT(w.cone_position(1).y, 0.9 - 0.01);
    EXPECT_FALSE(w.cone_doo(0));
    EXPECT_FALSE(w.cone_doo(1));
    EXPECT_EQ(w.bodies_in_world(), 0) << "all at rest again, off Box2D";
    // where the wind left it is its place now: a nudge of 8 mm from there is
    // no DOO (it would be from where it first stood)
    w.kick_cone(2, {0.3, 0.0});
    drive(w, [](double) { return Pose2{-50.0, 0.0, 0.0}; }, 3.0, 4.0);
    EXPECT_GT(w.cone_position(2).x - 40.0, 0.5);
    EXPECT_EQ(w.doo_count(), 0);
  }
}

TEST(ConeWorld, AConeTheWindMovedCountsWhenTheCarHitsItWhereItStands) {
  // the wind slides a cone 0.5 m into the car's lane; at rest, its new place
  // is its own: the car hitting it there at 10 m/s knocks it over (the car's
  // DOO); so does a cone the wind toppled, when the car then hits it
  const ConeWorldParams p;
  ConeWorld w({{{10.0, 0.7}, ConeColor::Yellow}, {{30.0, 0.5}, ConeColor::Yellow}}, p, kCar);
  w.disturb_cone(0, {0.0, -0.5}, false);
  w.disturb_cone(1, {0.0, -0.3}, true);
  // the car waits 1 s (the cones settle), then drives through both at 10 m/s
  const double x0 = -30.0;
  drive(w, [&](double t) { return Pose2{x0 + 10.0 * std::max(0.0, t - 1.0), 0.0, 0.0}; }, 0.0, 8.0);
  EXPECT_EQ(w.doo_cones(), (std::vector<int>{0, 1}));
  EXPECT_EQ(w.doo_events()[0].cause, DooCause::Knocked);
  // the wind had left cone 0 0.5 m further in: the car met it there
  EXPECT_GT(w.cone_position(0).x, 13.0);
  EXPECT_TRUE(w.cone_knocked(1));
}

TEST(ConeWorld, DisturbingChecksItsCone) {
  ConeWorld w({{{10.0, 0.7}, ConeColor::Yellow}}, ConeWorldParams{}, kCar);
  EXPECT_THROW(w.disturb_cone(1, {0.1, 0.0}, false), std::out_of_range);
  EXPECT_THROW(w.disturb_cone(-1, {0.1, 0.0}, false), std::out_of_range);
  w.disturb_cone(0, {std::nan(""), 0.0}, true);  // ignored
  EXPECT_FALSE(w.cone_knocked(0));
  drive(w, [](double) { return Pose2{-50.0, 0.0, 0.0}; }, 0.0, 1.0);
  EXPECT_EQ(w.cone_position(0).x, 10.0);
}

}  // namespace
}  // namespace paddock::world
