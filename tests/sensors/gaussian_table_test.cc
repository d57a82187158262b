// the shared table of Gaussian quantiles and its draw stream, against the
// normal distribution's own numbers: Phi through std::erfc, the std, the
// mass beyond 1, 2 and 3 sigma, and the uniformity of the 12-bit indices.
#include "sim/sensors/gaussian_table.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

namespace paddock::sensors {
namespace {

double phi(double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); }

TEST(GaussianTable, QuantilesAreThoseOfTheNormal) {
  const auto& q = gaussian_quantiles();
  ASSERT_EQ(q.size(), 4096u);
  double sum = 0.0, sum2 = 0.0;
  for (std::size_t k = 0; k < q.size(); ++k) {
    // Phi(q_k) = (k + 0.5) / 4096
    EXPECT_NEAR(phi(q[k]), (static_cast<double>(k) + 0.5) / 4096.0, 1e-12) << k;
    EXPECT_DOUBLE_EQ(q[k], -q[q.size() - 1 - k]) << k;
    if (k > 0) {
      EXPECT_LT(q[k - 1], q[k]);
    }
    sum += q[k];
    sum2 += q[k] * q[k];
  }
  const double mean = sum / 4096.0, std = std::sqrt(sum2 / 4096.0 - mean * mean);
  std::printf("table: cut at %.4f sigma, mean %.2e, std %.6f\n", q.back(), mean, std);
  // the documented figures: cut at 3.668 sigma, std within 0.02 % of 1
  EXPECT_NEAR(q.back(), 3.668, 0.001);
  EXPECT_NEAR(mean, 0.0, 1e-15);  // exactly symmetric, up to the sum's rounding
  EXPECT_NEAR(std, 1.0, 2e-4);
  EXPECT_LT(std, 1.0);  // the cut tails take a little of the variance
}

TEST(GaussianTable, FillGivesTheStreamsDraws) {
  // blocks of every length mod 5, from every position in a word
  GaussianStream a(777), b(777);
  std::vector<double> block;
  for (std::size_t n : {0u, 1u, 2u, 3u, 4u, 5u, 6u, 7u, 11u, 64u, 3u, 320u, 9u}) {
    block.assign(n, 0.0);
    a.fill(block.data(), n);
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_EQ(block[i], b()) << "block of " << n << ", draw " << i;
    }
  }
  EXPECT_EQ(a(), b());
}

TEST(GaussianTable, StreamDrawsAreStandardNormal) {
  GaussianStream g(12345);
  const int n = 1 << 22;  // 4 M draws
  double sum = 0.0, sum2 = 0.0;
  int beyond1 = 0, beyond2 = 0, beyond3 = 0;
  for (int i = 0; i < n; ++i) {
    const double x = g();
    sum += x;
    sum2 += x * x;
    beyond1 += std::abs(x) > 1.0;
    beyond2 += std::abs(x) > 2.0;
    beyond3 += std::abs(x) > 3.0;
  }
  const double mean = sum / n, std = std::sqrt(sum2 / n - mean * mean);
  const double f1 = double(beyond1) / n, f2 = double(beyond2) / n, f3 = double(beyond3) / n;
  std::printf("stream, %d draws: mean %.5f, std %.5f; beyond 1, 2, 3 sigma %.5f %.5f %.6f\n", n,
              mean, std, f1, f2, f3);
  // mean: 5 standard errors (1 / sqrt(n) = 4.9e-4); std within 0.3 % of 1
  EXPECT_NEAR(mean, 0.0, 0.0025);
  EXPECT_NEAR(std, 1.0, 0.003);
  // the normal's two-sided tail masses 2 (1 - Phi(k))
  EXPECT_NEAR(f1, 2.0 * (1.0 - phi(1.0)), 0.002);
  EXPECT_NEAR(f2, 2.0 * (1.0 - phi(2.0)), 0.001);
  EXPECT_NEAR(f3, 2.0 * (1.0 - phi(3.0)), 0.0003);
}

TEST(GaussianTable, IndicesAreUniformAndTheStreamRepeats) {
  GaussianStream a(7), b(7), c(8);
  std::vector<int> count(4096, 0);
  const int per_bin = 256, n = 4096 * per_bin;
  bool same = true, differs = false;
  for (int i = 0; i < n; ++i) {
    const std::uint32_t ia = a.index(), ib = b.index(), ic = c.index();
    ASSERT_LT(ia, 4096u);
    ++count[ia];
    same = same && ia == ib;
    differs = differs || ia != ic;
  }
  EXPECT_TRUE(same);
  EXPECT_TRUE(differs);
  // chi-square over the 4096 bins: 4095 degrees of freedom, mean 4095, std
  // sqrt(2 * 4095) = 90.5; 5 std either way
  double chi2 = 0.0;
  for (int k : count) chi2 += double(k - per_bin) * (k - per_bin) / per_bin;
  std::printf("indices: chi-square %.1f over 4095 degrees of freedom\n", chi2);
  EXPECT_NEAR(chi2, 4095.0, 5.0 * 90.5);
}

}  // namespace
}  // namespace paddock::sensors
