// the axes layer without pixels: nice ticks (brute-force checked over many
// ranges), tick labels without float noise, ranges, equal aspect, the data to
// pixel transform, the viridis table.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "render/plot.h"

namespace paddock::render {
namespace {

// step = m x 10^n with m in {1, 2, 5}
bool is_nice_step(double step) {
  const double n = std::floor(std::log10(step) + 1e-9);
  const double m = step / std::pow(10.0, n);
  return std::abs(m - 1.0) < 1e-9 || std::abs(m - 2.0) < 1e-9 || std::abs(m - 5.0) < 1e-9;
}

void expect_nice(double lo, double hi, int target = 6) {
  SCOPED_TRACE("range [" + std::to_string(lo) + ", " + std::to_string(hi) + "] target " + std::to_string(target));
  const Ticks t = nice_ticks(lo, hi, target);
  ASSERT_TRUE(is_nice_step(t.step)) << t.step;
  ASSERT_GE(t.values.size(), 4u);
  ASSERT_LE(t.values.size(), 10u);
  const double tol = 1e-9 * (hi - lo);
  for (std::size_t i = 0; i < t.values.size(); ++i) {
    const double v = t.values[i];
    // a multiple of the step ...
    const double k = std::round(v / t.step);
    EXPECT_NEAR(v, k * t.step, 1e-9 * t.step);
    // ... inside the range, ascending by one step
    EXPECT_GE(v, lo - tol);
    EXPECT_LE(v, hi + tol);
    if (i > 0) {
      EXPECT_NEAR(v - t.values[i - 1], t.step, 1e-9 * t.step);
    }
  }
  // covering it: no multiple of the step is left out at either end
  EXPECT_LT(t.values.front() - t.step, lo - tol);
  EXPECT_GT(t.values.back() + t.step, hi + tol);
  // the labels show every tick exactly and differ from each other
  std::vector<std::string> labels;
  for (double v : t.values) labels.push_back(format_number(v, t.decimals));
  for (std::size_t i = 0; i < labels.size(); ++i) {
    EXPECT_NEAR(std::stod(labels[i]), t.values[i], 1e-9 * t.step) << labels[i];
    EXPECT_LE(labels[i].size(), 16u) << labels[i];
    if (i > 0) {
      EXPECT_NE(labels[i], labels[i - 1]);
    }
  }
}

TEST(Ticks, RoundNumbersCoveringTheRange) {
  expect_nice(0.0, 1.0);
  expect_nice(-3.2, 17.9);
  expect_nice(1e-3, 5e-3);
  expect_nice(1000.0, 1003.0);
  expect_nice(-87.3, 9.6);
  expect_nice(0.0, 360.0);
  expect_nice(-0.13, 0.21);
  expect_nice(123456.0, 987654.0);
}

TEST(Ticks, BruteForceOverRandomRanges) {
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> exp10(-6.0, 6.0), unit(-1.0, 1.0);
  for (int i = 0; i < 3000; ++i) {
    const double span = std::pow(10.0, exp10(rng));
    const double centre = unit(rng) * span * std::pow(10.0, std::abs(unit(rng)) * 2.0);
    expect_nice(centre - 0.5 * span, centre + 0.5 * span);
    if (HasFailure()) break;
  }
}

TEST(Ticks, KnownSteps) {
  const Ticks a = nice_ticks(0.0, 1.0);
  EXPECT_DOUBLE_EQ(a.step, 0.2);
  ASSERT_EQ(a.values.size(), 6u);
  EXPECT_EQ(format_number(a.values[1], a.decimals), "0.2");
  EXPECT_EQ(format_number(a.values[3], a.decimals), "0.6");
  const Ticks b = nice_ticks(-3.2, 17.9);
  std::vector<std::string> labels;
  for (double v : b.values) labels.push_back(format_number(v, b.decimals));
  EXPECT_EQ(labels, (std::vector<std::string>{"0", "5", "10", "15"}));
  const Ticks c = nice_ticks(1000.0, 1003.0);
  EXPECT_DOUBLE_EQ(c.step, 0.5);
  EXPECT_EQ(format_number(c.values[1], c.decimals), "1000.5");
  // a degenerate range still gets ticks around it
  EXPECT_FALSE(nice_ticks(5.0, 5.0).values.empty());
  EXPECT_FALSE(nice_ticks(0.0, 0.0).values.empty());
  // a given step
  const Ticks d = ticks_with_step(-1.0, 1.0, 0.5);
  EXPECT_EQ(d.values, (std::vector<double>{-1.0, -0.5, 0.0, 0.5, 1.0}));
}

TEST(Ticks, LabelsWithoutFloatNoise) {
  EXPECT_EQ(format_number(0.1 + 0.2, 1), "0.3");
  EXPECT_EQ(format_number(3 * 0.1, 1), "0.3");
  EXPECT_EQ(format_number(-0.0, 0), "0");
  EXPECT_EQ(format_number(-1e-17, 2), "0.00");
  EXPECT_EQ(format_number(-5.0, 0), "-5");
  EXPECT_EQ(format_number(1e-3 * 3, 3), "0.003");
  EXPECT_EQ(format_tick(-5.0, 0), "\u22125");
  EXPECT_EQ(format_tick(5.0, 0), "5");
  EXPECT_EQ(format_compact(0.25), "0.25");
  EXPECT_EQ(format_compact(1500.0), "1500");
  EXPECT_EQ(format_compact(1e-5), "1e-05");
  EXPECT_EQ(decimals_for_step(0.2), 1);
  EXPECT_EQ(decimals_for_step(0.05), 2);
  EXPECT_EQ(decimals_for_step(5.0), 0);
  EXPECT_EQ(decimals_for_step(1e-3), 3);
}

TEST(Ranges, PaddedAndDegenerate) {
  Range r;
  EXPECT_TRUE(r.empty);
  const Range fallback = r.padded(0.1, 1.0, -2.0, 3.0);
  EXPECT_EQ(fallback.lo, -2.0);
  EXPECT_EQ(fallback.hi, 3.0);
  r.include(std::nan(""));
  EXPECT_TRUE(r.empty);
  r.include(4.0);
  const Range one = r.padded(0.1, 2.0);
  EXPECT_DOUBLE_EQ(one.lo, 3.0);
  EXPECT_DOUBLE_EQ(one.hi, 5.0);
  r.include(14.0);
  const Range two = r.padded(0.1, 2.0);
  EXPECT_DOUBLE_EQ(two.lo, 3.0);
  EXPECT_DOUBLE_EQ(two.hi, 15.0);
}

TEST(Frames, ToPixelAndEqualAspect) {
  AxesFrame f;
  f.plot = {100, 50, 700, 350};  // 600 x 300 px
  f.x_min = 0.0, f.x_max = 10.0, f.y_min = 0.0, f.y_max = 10.0;
  EXPECT_EQ(f.to_pixel({0.0, 0.0}), (Vec2{100.0, 350.0}));
  EXPECT_EQ(f.to_pixel({10.0, 10.0}), (Vec2{700.0, 50.0}));
  make_equal_aspect(f);
  // the y range (the short side in px) keeps its 10 m, x grows to 20 m about its centre
  EXPECT_DOUBLE_EQ(f.y_max - f.y_min, 10.0);
  EXPECT_DOUBLE_EQ(f.x_max - f.x_min, 20.0);
  EXPECT_DOUBLE_EQ(0.5 * (f.x_min + f.x_max), 5.0);
  const Vec2 a = f.to_pixel({0.0, 0.0}), b = f.to_pixel({10.0, 10.0});
  EXPECT_NEAR(b.x - a.x, a.y - b.y, 1e-9);
}

TEST(Viridis, EndsAndShape) {
  EXPECT_EQ(viridis(0.0), (Rgba{68, 1, 84, 255}));
  EXPECT_EQ(viridis(1.0), (Rgba{253, 231, 37, 255}));
  EXPECT_EQ(viridis(-3.0), viridis(0.0));
  EXPECT_EQ(viridis(7.0), viridis(1.0));
  EXPECT_EQ(viridis(std::nan("")), viridis(0.0));
  // 0.5 is half way between entries 127 and 128 of the table:
  // (0.128729 + 0.127568) / 2 * 255 = 32.7, (0.563265 + 0.566949) / 2 * 255 = 144.1, ...
  EXPECT_EQ(viridis(0.5), (Rgba{33, 144, 140, 255}));
  EXPECT_EQ(viridis(128.0 / 255.0), (Rgba{33, 145, 140, 255}));  // entry 128 itself
  // perceptually uniform: the luminance rises all the way
  double last = -1.0;
  for (int i = 0; i <= 100; ++i) {
    const Rgba c = viridis(i / 100.0);
    const double y = 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b;
    EXPECT_GT(y, last - 0.5) << i;
    last = y;
  }
}

}  // namespace
}  // namespace paddock::render
