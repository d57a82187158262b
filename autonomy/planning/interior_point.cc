#include "autonomy/planning/interior_point.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

namespace paddock::planning {

namespace {

// IPOPT's defaults (its options of the same names)
constexpr double kBoundPush = 1e-2;       // bound_push, bound_frac
constexpr double kMuInit = 0.1;           // mu_init
constexpr double kKappaEps = 10.0;        // barrier_tol_factor
constexpr double kKappaMu = 0.2;          // mu_linear_decrease_factor
constexpr double kThetaMu = 1.5;          // mu_superlinear_decrease_power
constexpr double kTauMin = 0.99;          // tau_min: fraction to the boundary
constexpr double kSMax = 100.0;           // s_max: scaling of the optimality error
constexpr double kKappaSigma = 1e10;      // kappa_sigma: how far z may stray from mu / s
constexpr double kArmijo = 1e-4;          // eta_phi
constexpr double kAcceptableTol = 1e-6;   // acceptable_tol
constexpr int kAcceptableIter = 15;       // acceptable_iter
constexpr int kMaxBacktracks = 60;
constexpr double kEps = std::numeric_limits<double>::epsilon();

using Index = Eigen::Index;

class Solver {
 public:
  Solver(const SparseLeastSquares& problem, const std::vector<double>& lower, const std::vector<double>& upper)
      : problem_(problem), lower_(lower), upper_(upper) {}

  InteriorPointResult run(std::vector<double>& x_io, const InteriorPointOptions& options);

 private:
  // f, and with grad the gradient over all the variables and the
  // Gauss-Newton Hessian's values (hessian_ in the pattern's order); false
  // when a residual is not finite
  bool evaluate(const std::vector<double>& x, double& f, bool derivatives);
  double barrier(const std::vector<double>& x, double f, double mu) const;
  void build_pattern();

  const SparseLeastSquares& problem_;
  const std::vector<double>& lower_;
  const std::vector<double>& upper_;
  std::vector<int> free_;        // the free variables
  std::vector<Index> column_;    // a variable's column among the free ones, -1 when fixed
  Eigen::SparseMatrix<double> H_;  // lower triangle over the free variables
  // per residual, the value index of each pair (p, q) of its variables, both
  // free, p's column >= q's (row-major in kMaxArity^2), -1 otherwise
  std::vector<Index> slots_;
  std::vector<Index> diagonal_;  // per free column, its diagonal value index
  std::vector<double> grad_;
};

void Solver::build_pattern() {
  const std::size_t m = problem_.residuals();
  constexpr std::size_t A = SparseLeastSquares::kMaxArity;
  std::vector<Eigen::Triplet<double>> entries;
  for (std::size_t c = 0; c < free_.size(); ++c) entries.emplace_back(static_cast<Index>(c), static_cast<Index>(c), 0.0);
  for (std::size_t k = 0; k < m; ++k) {
    const int* v = problem_.variables(k);
    for (std::size_t p = 0; p < problem_.arity(k); ++p)
      for (std::size_t q = 0; q < problem_.arity(k); ++q) {
        const Index a = column_[static_cast<std::size_t>(v[p])], b = column_[static_cast<std::size_t>(v[q])];
        if (a >= 0 && b >= 0 && a > b) entries.emplace_back(a, b, 0.0);
      }
  }
  H_.resize(static_cast<Index>(free_.size()), static_cast<Index>(free_.size()));
  H_.setFromTriplets(entries.begin(), entries.end());
  H_.makeCompressed();
  const double* base = H_.valuePtr();
  diagonal_.resize(free_.size());
  for (std::size_t c = 0; c < free_.size(); ++c)
    diagonal_[c] = &H_.coeffRef(static_cast<Index>(c), static_cast<Index>(c)) - base;
  slots_.assign(m * A * A, -1);
  for (std::size_t k = 0; k < m; ++k) {
    const int* v = problem_.variables(k);
    for (std::size_t p = 0; p < problem_.arity(k); ++p)
      for (std::size_t q = 0; q < problem_.arity(k); ++q) {
        const Index a = column_[static_cast<std::size_t>(v[p])], b = column_[static_cast<std::size_t>(v[q])];
        if (a >= 0 && b >= 0 && a >= b) slots_[(k * A + p) * A + q] = &H_.coeffRef(a, b) - base;
      }
  }
}

bool Solver::evaluate(const std::vector<double>& x, double& f, bool derivatives) {
  constexpr std::size_t A = SparseLeastSquares::kMaxArity;
  f = 0.0;
  double* h = H_.valuePtr();
  if (derivatives) {
    grad_.assign(x.size(), 0.0);
    std::fill(h, h + H_.nonZeros(), 0.0);
  }
  double j[A];
  for (std::size_t k = 0; k < problem_.residuals(); ++k) {
    const double r = problem_.residual(k, x.data(), derivatives ? j : nullptr);
    if (!std::isfinite(r)) return false;
    f += r * r;
    if (!derivatives) continue;
    const int* v = problem_.variables(k);
    const std::size_t arity = problem_.arity(k);
    for (std::size_t p = 0; p < arity; ++p) {
      if (!std::isfinite(j[p])) return false;
      grad_[static_cast<std::size_t>(v[p])] += 2.0 * r * j[p];
      for (std::size_t q = 0; q < arity; ++q) {
        const Index s = slots_[(k * A + p) * A + q];
        if (s >= 0) h[s] += 2.0 * j[p] * j[q];
      }
    }
  }
  return std::isfinite(f);
}

double Solver::barrier(const std::vector<double>& x, double f, double mu) const {
  double phi = f;
  for (int i : free_) {
    const std::size_t u = static_cast<std::size_t>(i);
    phi -= mu * (std::log(x[u] - lower_[u]) + std::log(upper_[u] - x[u]));
  }
  return phi;
}

InteriorPointResult Solver::run(std::vector<double>& x_io, const InteriorPointOptions& options) {
  InteriorPointResult out;
  const std::size_t n = lower_.size();
  if (upper_.size() != n || x_io.size() != n) {
    out.reason = "interior point: the bounds and the start differ in size";
    return out;
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(lower_[i]) || !std::isfinite(upper_[i]) || !std::isfinite(x_io[i]) || lower_[i] > upper_[i]) {
      out.reason = "interior point: variable " + std::to_string(i) + " has a non-finite or empty range, or start";
      return out;
    }
  }
  for (std::size_t k = 0; k < problem_.residuals(); ++k) {
    if (problem_.arity(k) > SparseLeastSquares::kMaxArity) {
      out.reason = "interior point: a residual of more than " + std::to_string(SparseLeastSquares::kMaxArity) +
                   " variables";
      return out;
    }
    for (std::size_t p = 0; p < problem_.arity(k); ++p) {
      const int v = problem_.variables(k)[p];
      if (v < 0 || static_cast<std::size_t>(v) >= n) {
        out.reason = "interior point: a residual names variable " + std::to_string(v) + " of " + std::to_string(n);
        return out;
      }
    }
  }

  // fixed variables at their bound; the others pushed inside theirs (IPOPT's
  // bound_push and bound_frac)
  std::vector<double> x = x_io;
  column_.assign(n, -1);
  free_.clear();
  for (std::size_t i = 0; i < n; ++i) {
    if (upper_[i] <= lower_[i]) {
      x[i] = lower_[i];
      continue;
    }
    column_[i] = static_cast<Index>(free_.size());
    free_.push_back(static_cast<int>(i));
    const double push_l = std::min(kBoundPush * std::max(1.0, std::abs(lower_[i])), kBoundPush * (upper_[i] - lower_[i]));
    const double push_u = std::min(kBoundPush * std::max(1.0, std::abs(upper_[i])), kBoundPush * (upper_[i] - lower_[i]));
    x[i] = std::clamp(x[i], lower_[i] + push_l, upper_[i] - push_u);
  }
  const std::size_t nf = free_.size();
  build_pattern();
  double f = 0.0;
  if (!evaluate(x, f, true)) {
    out.reason = "interior point: a residual is not finite at the start";
    return out;
  }
  const auto finish = [&](InteriorPointResult::Status status) {
    for (std::size_t i = 0; i < n; ++i) x_io[i] = std::clamp(x[i], lower_[i], upper_[i]);
    out.status = status;
    out.cost = f;
    return out;
  };
  if (nf == 0) {
    out.error = 0.0;
    return finish(InteriorPointResult::Status::Converged);
  }

  Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower> llt;
  llt.analyzePattern(H_);
  std::vector<double> zl(nf, 1.0), zu(nf, 1.0), sl(nf), su(nf);  // bound multipliers, slacks
  std::vector<double> dzl(nf), dzu(nf), trial(n);
  Eigen::VectorXd rhs(static_cast<Index>(nf)), dx(static_cast<Index>(nf));
  double mu = kMuInit;
  const double mu_min = options.tol / 10.0;  // IPOPT's: the barrier need not go further

  // the optimality error of the barrier problem for mu (0: the problem's own)
  const auto error = [&](double barrier_mu) {
    double zsum = 0.0, dual = 0.0, compl_ = 0.0;
    for (std::size_t c = 0; c < nf; ++c) {
      const std::size_t i = static_cast<std::size_t>(free_[c]);
      zsum += zl[c] + zu[c];
      dual = std::max(dual, std::abs(grad_[i] - zl[c] + zu[c]));
      compl_ = std::max({compl_, std::abs(sl[c] * zl[c] - barrier_mu), std::abs(su[c] * zu[c] - barrier_mu)});
    }
    const double s = std::max(kSMax, zsum / (2.0 * static_cast<double>(nf))) / kSMax;
    return std::max(dual / s, compl_ / s);
  };
  const auto slacks = [&](const std::vector<double>& at) {
    for (std::size_t c = 0; c < nf; ++c) {
      const std::size_t i = static_cast<std::size_t>(free_[c]);
      sl[c] = at[i] - lower_[i];
      su[c] = upper_[i] - at[i];
    }
  };
  slacks(x);

  int acceptable = 0;  // iterations in a row within the acceptable tolerance
  for (;;) {
    out.error = error(0.0);
    if (out.error <= options.tol) return finish(InteriorPointResult::Status::Converged);
    // (IPOPT's acceptable level: rounding can hold the error just above a
    // tight tolerance, and the iterates no longer move)
    acceptable = out.error <= std::max(kAcceptableTol, options.tol) ? acceptable + 1 : 0;
    if (acceptable >= kAcceptableIter) return finish(InteriorPointResult::Status::Acceptable);
    if (out.iterations >= options.max_iterations) return finish(InteriorPointResult::Status::MaxIterations);
    // the barrier parameter down while its own problem is solved well enough
    while (mu > mu_min && error(mu) <= kKappaEps * mu) {
      mu = std::max(mu_min, std::min(kKappaMu * mu, std::pow(mu, kThetaMu)));
    }
    const double tau = std::max(kTauMin, 1.0 - mu);

    // the Newton step of the barrier problem: (H + Sigma) dx = -grad phi_mu
    double* h = H_.valuePtr();
    double slope = 0.0;
    for (std::size_t c = 0; c < nf; ++c) {
      const std::size_t i = static_cast<std::size_t>(free_[c]);
      h[diagonal_[c]] += zl[c] / sl[c] + zu[c] / su[c];
      rhs[static_cast<Index>(c)] = -(grad_[i] - mu / sl[c] + mu / su[c]);
    }
    llt.factorize(H_);
    // H is positive semi-definite and Sigma positive: the factorisation
    // fails only on rounding; a small multiple of the identity then
    double delta = 0.0;
    while (llt.info() != Eigen::Success) {
      const double step = delta == 0.0 ? 1e-8 : 9.0 * delta;
      if (delta > 1e20) {
        out.reason = "interior point: the Newton system cannot be factorised";
        return finish(InteriorPointResult::Status::Stalled);
      }
      for (std::size_t c = 0; c < nf; ++c) h[diagonal_[c]] += step;
      delta += step;
      llt.factorize(H_);
    }
    dx = llt.solve(rhs);
    for (std::size_t c = 0; c < nf; ++c) slope -= rhs[static_cast<Index>(c)] * dx[static_cast<Index>(c)];
    if (!dx.allFinite()) {
      out.reason = "interior point: a non-finite Newton step";
      return finish(InteriorPointResult::Status::Stalled);
    }

    // the largest steps that keep the slacks and multipliers a fraction
    // tau of their distance from zero
    double alpha_x = 1.0, alpha_z = 1.0;
    for (std::size_t c = 0; c < nf; ++c) {
      const double d = dx[static_cast<Index>(c)];
      if (d < 0.0) alpha_x = std::min(alpha_x, -tau * sl[c] / d);
      if (d > 0.0) alpha_x = std::min(alpha_x, tau * su[c] / d);
      dzl[c] = mu / sl[c] - zl[c] - zl[c] / sl[c] * d;
      dzu[c] = mu / su[c] - zu[c] + zu[c] / su[c] * d;
      if (dzl[c] < 0.0) alpha_z = std::min(alpha_z, -tau * zl[c] / dzl[c]);
      if (dzu[c] < 0.0) alpha_z = std::min(alpha_z, -tau * zu[c] / dzu[c]);
    }

    // backtracking on the barrier function (with bounds only, the filter
    // line search's Armijo condition on phi_mu)
    const double phi = barrier(x, f, mu);
    double alpha = alpha_x, f_trial = 0.0;
    bool accepted = false;
    for (int b = 0; b < kMaxBacktracks && !accepted; ++b) {
      if (b > 0) alpha *= 0.5;
      trial = x;
      for (std::size_t c = 0; c < nf; ++c) trial[static_cast<std::size_t>(free_[c])] += alpha * dx[static_cast<Index>(c)];
      if (!evaluate(trial, f_trial, false)) continue;
      const double phi_trial = barrier(trial, f_trial, mu);
      // (IPOPT's comparison: within rounding of phi counts as no increase)
      accepted = std::isfinite(phi_trial) &&
                 phi_trial - phi <= kArmijo * alpha * slope + 10.0 * kEps * std::abs(phi);
    }
    if (!accepted) {
      out.reason = "interior point: no step decreases the barrier function";
      return finish(InteriorPointResult::Status::Stalled);
    }
    x.swap(trial);
    for (std::size_t c = 0; c < nf; ++c) {
      zl[c] += alpha_z * dzl[c];
      zu[c] += alpha_z * dzu[c];
    }
    slacks(x);
    // the multipliers kept within a factor kappa_sigma of mu / slack
    for (std::size_t c = 0; c < nf; ++c) {
      zl[c] = std::clamp(zl[c], mu / (kKappaSigma * sl[c]), kKappaSigma * mu / sl[c]);
      zu[c] = std::clamp(zu[c], mu / (kKappaSigma * su[c]), kKappaSigma * mu / su[c]);
    }
    ++out.iterations;
    if (!evaluate(x, f, true)) {
      out.reason = "interior point: a residual's derivative is not finite";
      return finish(InteriorPointResult::Status::Stalled);
    }
  }
}

}  // namespace

InteriorPointResult minimise_within_bounds(const SparseLeastSquares& problem, const std::vector<double>& lower,
                                           const std::vector<double>& upper, std::vector<double>& x,
                                           const InteriorPointOptions& options) {
  Solver solver(problem, lower, upper);
  return solver.run(x, options);
}

}  // namespace paddock::planning
