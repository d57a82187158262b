// gates from big orange cones: the rules' acceleration layout (two cones a
// side at each line) and a circuit's timekeeping posts
#include "autonomy/stack/gates.h"

#include <gtest/gtest.h>

#include "autonomy/common/polyline.h"

namespace paddock::stack {
namespace {

TEST(Gates, AccelerationLayoutGivesTwoGates) {
  std::vector<Cone> cones;
  for (double x : {-0.3, 0.3, 74.7, 75.3})
    for (double y : {1.9, -1.9}) cones.push_back({{x, y}, ConeColor::BigOrange});
  // lane cones do not take part
  for (int i = 0; i < 20; ++i) cones.push_back({{5.0 * i, 1.9}, ConeColor::Blue});
  auto gates = find_gates(cones);
  ASSERT_EQ(gates.size(), 2u);
  for (auto& g : gates) g = orient_gate(g, {1.0, 0.0});
  // each gate is across the lane at its line, left post (y > 0) first
  for (const auto& g : gates) {
    EXPECT_NEAR(g.a.y, 1.9, 1e-12);
    EXPECT_NEAR(g.b.y, -1.9, 1e-12);
    EXPECT_NEAR(g.a.x, g.b.x, 1e-12);
  }
  // driving +x crosses each from right to left
  for (const auto& g : gates) {
    const double x = g.a.x;
    EXPECT_TRUE(crossing_right_to_left({x - 1.0, 0.0}, {x + 1.0, 0.0}, g).has_value());
    EXPECT_FALSE(crossing_right_to_left({x + 1.0, 0.0}, {x - 1.0, 0.0}, g).has_value());
  }
}

TEST(Gates, TooNarrowOrTooWideOrLonelyPostsMakeNoGate) {
  EXPECT_TRUE(find_gates({{{0, 0}, ConeColor::BigOrange}}).empty());
  EXPECT_TRUE(find_gates({{{0, 0}, ConeColor::BigOrange}, {{0, 1.5}, ConeColor::BigOrange}}).empty());
  EXPECT_TRUE(find_gates({{{0, 0}, ConeColor::BigOrange}, {{0, 25}, ConeColor::BigOrange}}).empty());
  EXPECT_TRUE(find_gates({}).empty());
  // a circuit's posts 8 m apart across the start straight
  const auto g = find_gates({{{7.68, 4.0}, ConeColor::BigOrange}, {{7.68, -4.0}, ConeColor::BigOrange}});
  ASSERT_EQ(g.size(), 1u);
  const Segment o = orient_gate(g[0], {1.0, 0.0});
  EXPECT_EQ(o.a.y, 4.0);
}

}  // namespace
}  // namespace paddock::stack
