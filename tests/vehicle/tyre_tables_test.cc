// tests of the tyre curve's tables (tyre_tables.h) against the functions they
// tabulate, evaluated afresh in long double at points the build never saw,
// and of the tabulated tyre force against the curve as written
#include "sim/vehicle/tyre_tables.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include "sim/vehicle/vehicle.h"

namespace paddock::vehicle {
namespace {

long double curve_ratio_exact(long double c, long double e, long double s) {
  if (s <= 0.0L) return c;
  const long double x = std::sqrt(s);
  return std::sin(c * std::atan(x - e * (x - std::atan(x)))) / x;
}

// arguments across the table: uniform over [0, kMax), and log-spaced down to 2^-40
std::vector<double> arguments(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> s{0.0, EvenTable::kFirst, 1.0, 0x1.fffffffffffffp5};
  for (int i = 0; i < 20000; ++i) s.push_back(u(rng) * EvenTable::kMax);
  for (int i = 0; i < 20000; ++i) s.push_back(std::ldexp(u(rng), -(i % 40)) * EvenTable::kMax);
  return s;
}

TEST(TyreTables, MatchTheCurveAcrossTheWholeRangeOfCAndE) {
  // C in (0, 2], E in [-5, 1]: VehicleParams' bounds
  double worst = 0.0;
  for (const double c : {0.05, 0.6, 1.2, 1.45, 1.7, 2.0}) {
    for (const double e : {-5.0, -2.0, -0.3, 0.0, 0.6, 0.97, 1.0}) {
      const TyreTables t(c, e);
      EXPECT_LE(t.error, 2e-14) << "C " << c << " E " << e;
      for (const double s : arguments(17)) {
        const long double exact = curve_ratio_exact(c, e, s);
        const double err = static_cast<double>(std::abs((t.curve_ratio.at(s) - exact) / exact));
        worst = std::max(worst, err);
        ASSERT_LE(err, 2e-14) << "C " << c << " E " << e << " s " << s;
      }
    }
  }
  std::printf("curve_ratio: worst relative error %.3g\n", worst);
}

TEST(TyreTables, TheAtanRatioGivesAtanWithinAFewUlp) {
  const TyreTables t(1.45, -0.3);
  double worst = 0.0;
  for (const double s : arguments(5)) {
    const long double r = std::sqrt(static_cast<long double>(s));
    const long double exact = s == 0.0 ? 1.0L : std::atan(r) / r;
    worst = std::max(worst, static_cast<double>(std::abs((t.atan_ratio.at(s) - exact) / exact)));
  }
  EXPECT_LE(worst, 2e-15);
  std::printf("atan_ratio: worst relative error %.3g\n", worst);
}

TEST(TyreTables, TheLanesComputeWhatOneArgumentDoes) {
  // the vehicle evaluates four tyres at once: each lane's bits are the
  // scalar's, and a lane outside [0, kMax) or NaN does not disturb the others
  const TyreTables t(1.38, -0.58);
  const std::vector<double> s = arguments(3);
  for (std::size_t i = 0; i + 3 < s.size(); i += 4) {
    const simd::D4 v = t.curve_ratio(simd::D4{s[i], s[i + 1], s[i + 2], s[i + 3]});
    for (std::size_t j = 0; j < 4; ++j) ASSERT_EQ(v[j], t.curve_ratio.at(s[i + j])) << s[i + j];
  }
  const simd::D4 odd = t.curve_ratio(simd::D4{-1.0, std::nan(""), EvenTable::kMax, 2.0});
  EXPECT_EQ(odd[0], t.curve_ratio.at(0.0));
  EXPECT_EQ(odd[1], t.curve_ratio.at(0.0));
  EXPECT_EQ(odd[2], t.curve_ratio.at(0.0));
  EXPECT_EQ(odd[3], t.curve_ratio.at(2.0));
}

TEST(TyreTables, TheBuildSeesAFunctionItCannotFollow) {
  // a kink inside a cell: the measured error says so (the car would then
  // take the curve as written)
  EvenTable kinked;
  EXPECT_GT(kinked.build([](long double s) { return 1.0L + std::sqrt(std::abs(s - 1.03L)); }), 1e-3);
  EvenTable smooth;
  EXPECT_LE(smooth.build([](long double s) { return 1.0L + s * s * s; }), 2e-15);
}

TEST(TyreTables, TheCarsTyreForceIsTheCurveAsWritten) {
  // what step() computes against tyre_force on the parameters: slips inside
  // the table and beyond it (X > 8, where the car takes the curve as written)
  const std::pair<double, double> curves[] = {{1.45, -0.3}, {1.38, -0.58}, {2.0, -5.0}, {0.6, 1.0}};  // C, E
  for (const auto& [c, e] : curves) {
    VehicleParams p;  // the tyre's parameters: nothing else shapes its force
    p.tyre_b = 10.0;
    p.tyre_bx = 12.0;
    p.tyre_c = c;
    p.tyre_e = e;
    p.tyre_d = 1.6;
    p.tyre_dx = 1.5;
    p.tyre_load_nominal = 700.0;
    p.tyre_load_sensitivity = -0.1;
    p.relaxation_length_x = p.relaxation_length_y = 0.2;
    const Car car(p);
    ASSERT_NE(car.tyres(), nullptr);
    double worst = 0.0;
    for (double kappa = -1.0; kappa <= 1.0; kappa += 0.0125) {
      for (double alpha = -0.9; alpha <= 0.9; alpha += 0.0111) {
        for (const double fz : {0.0, 350.0, 900.0}) {
          const TyreForce a = tyre_force(p, kappa, alpha, fz);
          const TyreForce b = tyre_force(car, kappa, alpha, fz);
          const double scale = std::max(1.0, std::hypot(a.fx, a.fy));
          worst = std::max({worst, std::abs(a.fx - b.fx) / scale, std::abs(a.fy - b.fy) / scale});
        }
      }
    }
    EXPECT_LE(worst, 1e-13) << "C " << c << " E " << e;
    std::printf("C %.2f E %.2f: the tabulated force within %.3g of the curve's (relative)\n", c, e, worst);
  }
}

}  // namespace
}  // namespace paddock::vehicle
