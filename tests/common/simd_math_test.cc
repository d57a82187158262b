// simd::atan, sin and cos against glibc's (std::atan, std::sin, std::cos,
// themselves within an ulp of the true value): the error in units in the
// last place over a million arguments, near the folds and spread over many
// orders of magnitude; the special values one by one; and the same lanes
// built for AVX2 and for baseline x86-64 giving the same bits.
#include "autonomy/common/simd_math.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "tests/common/ulps.h"

namespace paddock {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

using testing::ulps;

struct Lanes {
  double atan[4], sin[4], cos[4];
};

PADDOCK_SIMD_INLINE Lanes evaluate(const double* x) {
  Lanes out;
  const simd::D4 v = simd::load(x);
  simd::store(out.atan, simd::atan(v));
  simd::D4 s, c;
  simd::sincos(v, s, c);
  simd::store(out.sin, s);
  simd::store(out.cos, c);
  return out;
}

Lanes evaluate_baseline(const double* x) { return evaluate(x); }
#if defined(__x86_64__)
__attribute__((target("avx2"))) Lanes evaluate_avx2(const double* x) { return evaluate(x); }
#endif

// arguments: uniform on [-lo, lo] for the first half, log-uniform from 1e-12 to hi after
std::vector<double> arguments(double lo, double hi, int n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-lo, lo), e(-12.0, std::log10(hi)), half(0.0, 1.0);
  std::vector<double> xs;
  for (int i = 0; i < n; ++i) {
    const double m = i % 2 == 0 ? u(rng) : std::pow(10.0, e(rng));
    xs.push_back(i % 2 == 1 && half(rng) < 0.5 ? -m : m);
  }
  return xs;
}

TEST(SimdMath, AtanIsWithinOneUlpOfTheLibrary) {
  const std::vector<double> xs = arguments(3.0, 1e20, 1000000, 3);  // both folds, 0.66 and tan(3 pi/8)
  double worst = 0.0;
  for (std::size_t i = 0; i + 4 <= xs.size(); i += 4) {
    const Lanes l = evaluate(&xs[i]);
    for (int k = 0; k < 4; ++k) worst = std::max(worst, ulps(l.atan[k], std::atan(xs[i + k])));
  }
  std::printf("simd::atan: worst %.2f ulp\n", worst);
  EXPECT_LE(worst, 1.0);
}

TEST(SimdMath, SinAndCosAreWithinTwoUlpOfTheLibrary) {
  // the tyre's C atan(.) stays within +-C pi/2; a wrapped yaw within +-pi;
  // out to 1e5 rad the three-part reduction still holds
  const std::vector<double> xs = arguments(2.0 * M_PI, 1e5, 1000000, 4);
  double worst_sin = 0.0, worst_cos = 0.0, worst_abs = 0.0;
  for (std::size_t i = 0; i + 4 <= xs.size(); i += 4) {
    const Lanes l = evaluate(&xs[i]);
    for (int k = 0; k < 4; ++k) {
      const double x = xs[i + k];
      worst_abs = std::max({worst_abs, std::abs(l.sin[k] - std::sin(x)), std::abs(l.cos[k] - std::cos(x))});
      // near a zero of the function the ulp is tiny: there the absolute error counts
      if (std::abs(std::sin(x)) > 1e-3) worst_sin = std::max(worst_sin, ulps(l.sin[k], std::sin(x)));
      if (std::abs(std::cos(x)) > 1e-3) worst_cos = std::max(worst_cos, ulps(l.cos[k], std::cos(x)));
    }
  }
  std::printf("simd::sin: worst %.2f ulp, simd::cos: worst %.2f ulp, absolute %.3g\n", worst_sin, worst_cos, worst_abs);
  EXPECT_LE(worst_sin, 2.0);  // the reduced argument carries no tail (fdlibm's y): 2 ulp, not 1
  EXPECT_LE(worst_cos, 2.0);
  EXPECT_LE(worst_abs, 2e-16 * 1e5);  // an ulp of the reduced argument's largest multiple
}

TEST(SimdMath, SpecialValuesAreTheLibrarys) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double in[4] = {kInf, -kInf, 0.0, -0.0};
  const Lanes l = evaluate(in);
  EXPECT_EQ(l.atan[0], std::atan(kInf));
  EXPECT_EQ(l.atan[1], std::atan(-kInf));
  EXPECT_EQ(l.atan[2], 0.0);
  EXPECT_FALSE(std::signbit(l.atan[2]));
  EXPECT_EQ(l.atan[3], 0.0);
  EXPECT_TRUE(std::signbit(l.atan[3]));
  EXPECT_EQ(l.sin[2], 0.0);
  EXPECT_EQ(l.cos[2], 1.0);
  EXPECT_TRUE(std::isnan(l.sin[0]));  // sin(inf): NaN, as the library's
  EXPECT_TRUE(std::isnan(l.cos[1]));
  const double nans[4] = {nan, 1.0, -nan, 2.0};
  const Lanes n = evaluate(nans);
  EXPECT_TRUE(std::isnan(n.atan[0]) && std::isnan(n.sin[0]) && std::isnan(n.cos[0]));
  EXPECT_TRUE(std::isnan(n.atan[2]) && std::isnan(n.sin[2]) && std::isnan(n.cos[2]));
  // a NaN lane leaves its neighbours alone
  EXPECT_NEAR(n.atan[1], std::atan(1.0), 1e-16);
  EXPECT_NEAR(n.sin[3], std::sin(2.0), 1e-16);
}

TEST(SimdMath, Avx2AndBaselineBuildsGiveTheSameBits) {
#if defined(__x86_64__)
  __builtin_cpu_init();
  if (!__builtin_cpu_supports("avx2")) GTEST_SKIP() << "no AVX2 on this CPU";
  const std::vector<double> xs = arguments(4.0, 1e6, 200000, 5);
  std::size_t differ = 0;
  for (std::size_t i = 0; i + 4 <= xs.size(); i += 4) {
    const Lanes a = evaluate_avx2(&xs[i]), b = evaluate_baseline(&xs[i]);
    differ += std::memcmp(&a, &b, sizeof a) != 0;
  }
  EXPECT_EQ(differ, 0u);
#else
  GTEST_SKIP() << "not x86-64";
#endif
}

}  // namespace
}  // namespace paddock
