// the interior-point solver against closed forms (a separable quadratic:
// the clamped target), the optimality conditions at its answer, and IPOPT
// itself (the reference implementation of the algorithm, linked into this
// test only) on curvature problems shaped like the racing line's.
#include "autonomy/planning/interior_point.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <memory>
#include <random>
#include <vector>

#include <ceres/ceres.h>
#include <IpIpoptApplication.hpp>
#include <IpTNLP.hpp>

namespace paddock::planning {
namespace {

// r_i = w_i (x_i - c_i): the minimum within the bounds is c clamped
class Separable : public SparseLeastSquares {
 public:
  Separable(std::vector<double> c, std::vector<double> w) : c_(std::move(c)), w_(std::move(w)) {
    for (std::size_t i = 0; i < c_.size(); ++i) index_.push_back(static_cast<int>(i));
  }
  std::size_t residuals() const override { return c_.size(); }
  std::size_t arity(std::size_t) const override { return 1; }
  const int* variables(std::size_t k) const override { return &index_[k]; }
  double residual(std::size_t k, const double* x, double* j) const override {
    if (j) j[0] = w_[k];
    return w_[k] * (x[k] - c_[k]);
  }

 private:
  std::vector<double> c_, w_;
  std::vector<int> index_;
};

// the racing line's problem: points of a wobbly loop (or open chain), each
// moved along its normal by x_i, the Menger curvature of each three
// neighbours times sqrt(ds) a residual; plus, when `pull` is non-zero, a
// pull of each point towards its own target offset (a convex term)
struct Menger {
  double p[6], n[6];
  template <class T>
  bool operator()(const T* a0, const T* a1, const T* a2, T* r) const {
    using std::sqrt;
    const T x0 = p[0] + a0[0] * n[0], y0 = p[1] + a0[0] * n[1];
    const T x1 = p[2] + a1[0] * n[2], y1 = p[3] + a1[0] * n[3];
    const T x2 = p[4] + a2[0] * n[4], y2 = p[5] + a2[0] * n[5];
    const T ax = x1 - x0, ay = y1 - y0, bx = x2 - x1, by = y2 - y1, cx = x2 - x0, cy = y2 - y0;
    const T la = sqrt(ax * ax + ay * ay), lb = sqrt(bx * bx + by * by), lc = sqrt(cx * cx + cy * cy);
    r[0] = sqrt(0.5 * (la + lb)) * 2.0 * (ax * by - ay * bx) / (la * lb * lc);
    return true;
  }
};

class Chain : public SparseLeastSquares {
 public:
  Chain(std::size_t n, bool closed, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> wobble(-0.15, 0.15), phase(0.0, 6.28);
    const double ph = phase(rng), radius = 4.0 + static_cast<double>(n) / 6.2832;
    std::vector<double> px(n), py(n);
    for (std::size_t i = 0; i < n; ++i) {
      const double a = 6.2832 * static_cast<double>(i) / static_cast<double>(n);
      const double r = radius * (1.0 + 0.2 * std::sin(3.0 * a + ph) + wobble(rng) / radius);
      px[i] = r * std::cos(a);
      py[i] = (closed ? 1.0 : 0.6) * r * std::sin(a);
    }
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t a = closed ? (i + n - 1) % n : (i == 0 ? 0 : i - 1);
      const std::size_t b = closed ? (i + 1) % n : std::min(i + 1, n - 1);
      const double tx = px[b] - px[a], ty = py[b] - py[a], len = std::hypot(tx, ty);
      nx_.push_back(-ty / len);
      ny_.push_back(tx / len);
    }
    for (std::size_t i = closed ? 0 : 1; i < (closed ? n : n - 1); ++i) {
      const std::size_t a = (i + n - 1) % n, c = (i + 1) % n;
      auto* m = new Menger{{px[a], py[a], px[i], py[i], px[c], py[c]}, {nx_[a], ny_[a], nx_[i], ny_[i], nx_[c], ny_[c]}};
      terms_.push_back({{static_cast<int>(a), static_cast<int>(i), static_cast<int>(c)},
                        std::make_unique<ceres::AutoDiffCostFunction<Menger, 1, 1, 1, 1>>(m)});
    }
    size_ = n;
  }
  std::size_t residuals() const override { return terms_.size(); }
  std::size_t arity(std::size_t) const override { return 3; }
  const int* variables(std::size_t k) const override { return terms_[k].index; }
  double residual(std::size_t k, const double* x, double* j) const override {
    const Term& t = terms_[k];
    const double* params[3] = {&x[t.index[0]], &x[t.index[1]], &x[t.index[2]]};
    double* jac[3] = {j, j ? j + 1 : nullptr, j ? j + 2 : nullptr};
    double r = 0.0;
    t.cost->Evaluate(params, &r, j ? jac : nullptr);
    return r;
  }
  std::size_t size() const { return size_; }

 private:
  struct Term {
    int index[3];
    std::unique_ptr<ceres::CostFunction> cost;
  };
  std::vector<Term> terms_;
  std::vector<double> nx_, ny_;
  std::size_t size_ = 0;
};

double cost_of(const SparseLeastSquares& p, const std::vector<double>& x) {
  double f = 0.0;
  for (std::size_t k = 0; k < p.residuals(); ++k) f += std::pow(p.residual(k, x.data(), nullptr), 2);
  return f;
}

std::vector<double> gradient_of(const SparseLeastSquares& p, const std::vector<double>& x) {
  std::vector<double> g(x.size(), 0.0);
  double j[SparseLeastSquares::kMaxArity];
  for (std::size_t k = 0; k < p.residuals(); ++k) {
    const double r = p.residual(k, x.data(), j);
    for (std::size_t q = 0; q < p.arity(k); ++q) g[static_cast<std::size_t>(p.variables(k)[q])] += 2.0 * r * j[q];
  }
  return g;
}

// IPOPT on the same problem: its exact Hessian approximated the same way
// (Gauss-Newton, dense lower triangle: the problems here are small)
class IpoptProblem : public Ipopt::TNLP {
 public:
  using Index = Ipopt::Index;
  using Number = Ipopt::Number;
  IpoptProblem(const SparseLeastSquares& p, const std::vector<double>& lo, const std::vector<double>& hi,
               std::vector<double>& x)
      : p_(p), lo_(lo), hi_(hi), x_(x) {}
  bool get_nlp_info(Index& n, Index& m, Index& nnz_jac, Index& nnz_h, IndexStyleEnum& style) override {
    n = static_cast<Index>(x_.size());
    m = 0;
    nnz_jac = 0;
    nnz_h = n * (n + 1) / 2;
    style = C_STYLE;
    return true;
  }
  bool get_bounds_info(Index n, Number* xl, Number* xu, Index, Number*, Number*) override {
    for (Index i = 0; i < n; ++i) xl[i] = lo_[static_cast<std::size_t>(i)], xu[i] = hi_[static_cast<std::size_t>(i)];
    return true;
  }
  bool get_starting_point(Index n, bool, Number* x, bool, Number*, Number*, Index, bool, Number*) override {
    std::copy(x_.begin(), x_.begin() + n, x);
    return true;
  }
  bool eval_f(Index n, const Number* x, bool, Number& f) override {
    f = cost_of(p_, std::vector<double>(x, x + n));
    return true;
  }
  bool eval_grad_f(Index n, const Number* x, bool, Number* g) override {
    const std::vector<double> grad = gradient_of(p_, std::vector<double>(x, x + n));
    std::copy(grad.begin(), grad.end(), g);
    return true;
  }
  bool eval_g(Index, const Number*, bool, Index, Number*) override { return true; }
  bool eval_jac_g(Index, const Number*, bool, Index, Index, Index*, Index*, Number*) override { return true; }
  bool eval_h(Index n, const Number* x, bool, Number obj, Index, const Number*, bool, Index nele, Index* row,
              Index* col, Number* values) override {
    if (values == nullptr) {
      Index s = 0;
      for (Index i = 0; i < n; ++i)
        for (Index j = 0; j <= i; ++j) row[s] = i, col[s] = j, ++s;
      return true;
    }
    std::fill(values, values + nele, 0.0);
    double jac[SparseLeastSquares::kMaxArity];
    for (std::size_t k = 0; k < p_.residuals(); ++k) {
      p_.residual(k, x, jac);
      for (std::size_t a = 0; a < p_.arity(k); ++a)
        for (std::size_t b = 0; b < p_.arity(k); ++b) {
          const Index i = p_.variables(k)[a], j = p_.variables(k)[b];
          if (i >= j) values[i * (i + 1) / 2 + j] += obj * 2.0 * jac[a] * jac[b];
        }
    }
    return true;
  }
  void finalize_solution(Ipopt::SolverReturn, Index n, const Number* x, const Number*, const Number*, Index,
                         const Number*, const Number*, Number, const Ipopt::IpoptData*,
                         Ipopt::IpoptCalculatedQuantities*) override {
    std::copy(x, x + n, x_.begin());
  }

 private:
  const SparseLeastSquares& p_;
  const std::vector<double>& lo_;
  const std::vector<double>& hi_;
  std::vector<double>& x_;
};

bool ipopt_solve(const SparseLeastSquares& p, const std::vector<double>& lo, const std::vector<double>& hi,
                 std::vector<double>& x) {
  Ipopt::SmartPtr<IpoptProblem> nlp = new IpoptProblem(p, lo, hi, x);
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app = IpoptApplicationFactory();
  app->Options()->SetIntegerValue("print_level", 0);
  app->Options()->SetStringValue("sb", "yes");
  app->Options()->SetNumericValue("tol", 1e-12);
  app->Options()->SetIntegerValue("max_iter", 1000);
  if (app->Initialize() != Ipopt::Solve_Succeeded) return false;
  const Ipopt::ApplicationReturnStatus s = app->OptimizeTNLP(Ipopt::SmartPtr<Ipopt::TNLP>(GetRawPtr(nlp)));
  return s == Ipopt::Solve_Succeeded || s == Ipopt::Solved_To_Acceptable_Level;
}

// random bounds round 0 (the start), some tight, some equal (fixed)
void random_bounds(std::size_t n, unsigned seed, std::vector<double>& lo, std::vector<double>& hi) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> width(0.05, 2.5), u(0.0, 1.0);
  lo.resize(n);
  hi.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    lo[i] = -width(rng);
    hi[i] = width(rng);
    if (u(rng) < 0.05) lo[i] = hi[i] = 0.0;
  }
}

TEST(InteriorPoint, ASeparableQuadraticGivesItsTargetClamped) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> c(-3.0, 3.0), w(0.1, 10.0);
  std::vector<double> target(50), weight(50), lo(50, -1.0), hi(50, 1.5);
  for (std::size_t i = 0; i < 50; ++i) target[i] = c(rng), weight[i] = w(rng);
  lo[7] = hi[7] = 0.25;  // fixed
  const Separable problem(target, weight);
  std::vector<double> x(50, 0.0);
  const InteriorPointResult res = minimise_within_bounds(problem, lo, hi, x);
  ASSERT_EQ(res.status, InteriorPointResult::Status::Converged) << res.reason;
  for (std::size_t i = 0; i < 50; ++i) EXPECT_NEAR(x[i], std::clamp(target[i], lo[i], hi[i]), 1e-8) << i;
  EXPECT_EQ(x[7], 0.25);
  EXPECT_GT(res.iterations, 3);
  EXPECT_LT(res.iterations, 60);
}

TEST(InteriorPoint, MeetsTheOptimalityConditionsAndIpoptsCostOnCurvatureProblems) {
  // 24 problems of the racing line's shape, closed and open, 20 to 200
  // variables: the same local minimum as IPOPT (from the same start), and
  // there the first-order conditions hold: the gradient vanishes at a
  // free variable and points outwards at an active bound
  int active = 0;
  for (unsigned seed = 1; seed <= 24; ++seed) {
    const bool closed = seed % 2 == 0;
    const std::size_t n = 20 + (seed * 37) % 181;
    const Chain problem(n, closed, seed);
    std::vector<double> lo, hi;
    random_bounds(n, seed + 100, lo, hi);
    std::vector<double> x(n, 0.0), x_ipopt(n, 0.0);
    const InteriorPointResult res = minimise_within_bounds(problem, lo, hi, x);
    ASSERT_EQ(res.status, InteriorPointResult::Status::Converged) << seed << ": " << res.reason << " error " << res.error << " after " << res.iterations;
    ASSERT_TRUE(ipopt_solve(problem, lo, hi, x_ipopt)) << seed;
    const double f = cost_of(problem, x), f_ipopt = cost_of(problem, x_ipopt);
    EXPECT_NEAR(res.cost, f, 1e-12 * (1.0 + f)) << seed;
    EXPECT_LE(f, f_ipopt + 1e-9 * (1.0 + f_ipopt)) << seed;
    EXPECT_NEAR(f, f_ipopt, 1e-7 * (1.0 + f_ipopt)) << seed;
    double worst = 0.0;
    for (std::size_t i = 0; i < n; ++i) worst = std::max(worst, std::abs(x[i] - x_ipopt[i]));
    EXPECT_LT(worst, 1e-4) << seed << " (n " << n << ")";
    const std::vector<double> g = gradient_of(problem, x);
    const double scale = 1e-6 * (1.0 + *std::max_element(g.begin(), g.end(), [](double a, double b) {
      return std::abs(a) < std::abs(b);
    }));
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_GE(x[i], lo[i]);
      ASSERT_LE(x[i], hi[i]);
      if (lo[i] == hi[i]) continue;
      const bool at_lo = x[i] - lo[i] < 1e-5, at_hi = hi[i] - x[i] < 1e-5;  // (an interior point stays mu / z inside)
      active += at_lo || at_hi;
      if (at_lo) {
        EXPECT_GE(g[i], -1e-7) << seed << " variable " << i;
      } else if (at_hi) {
        EXPECT_LE(g[i], 1e-7) << seed << " variable " << i;
      } else {
        EXPECT_LT(std::abs(g[i]), std::max(scale, 1e-7)) << seed << " variable " << i;
      }
    }
  }
  EXPECT_GT(active, 100);  // the bounds mattered
}

TEST(InteriorPoint, StopsAtItsIterationLimitWithinTheBounds) {
  const Chain problem(120, true, 5);
  std::vector<double> lo, hi;
  random_bounds(120, 105, lo, hi);
  std::vector<double> x(120, 0.0);
  InteriorPointOptions o;
  o.max_iterations = 3;
  const double f0 = cost_of(problem, std::vector<double>(120, 0.0));
  const InteriorPointResult res = minimise_within_bounds(problem, lo, hi, x, o);
  EXPECT_EQ(res.status, InteriorPointResult::Status::MaxIterations);
  EXPECT_TRUE(res.usable());
  EXPECT_EQ(res.iterations, 3);
  EXPECT_LT(res.cost, f0);
  for (std::size_t i = 0; i < 120; ++i) EXPECT_TRUE(x[i] >= lo[i] && x[i] <= hi[i]) << i;
}

TEST(InteriorPoint, BadInputFailsWithAReasonAndLeavesTheStart) {
  const Separable problem({1.0, 2.0}, {1.0, 1.0});
  std::vector<double> x{0.5, 0.5};
  const auto fails = [&](std::vector<double> lo, std::vector<double> hi, std::vector<double> start) {
    x = start;
    const InteriorPointResult r = minimise_within_bounds(problem, lo, hi, x);
    EXPECT_FALSE(r.usable());
    EXPECT_FALSE(r.reason.empty());
    ASSERT_EQ(x.size(), start.size());
    for (std::size_t i = 0; i < x.size(); ++i) EXPECT_TRUE(x[i] == start[i] || (std::isnan(x[i]) && std::isnan(start[i])));
  };
  fails({0.0}, {1.0, 1.0}, {0.5, 0.5});                        // sizes
  fails({0.0, 1.0}, {1.0, 0.5}, {0.5, 0.5});                   // lower > upper
  fails({0.0, std::nan("")}, {1.0, 1.0}, {0.5, 0.5});          // NaN bound
  fails({0.0, 0.0}, {1.0, 1.0}, {0.5, std::nan("")});          // NaN start
  fails({0.0, 0.0}, {1.0, HUGE_VAL}, {0.5, 0.5});              // infinite bound
}

}  // namespace
}  // namespace paddock::planning
