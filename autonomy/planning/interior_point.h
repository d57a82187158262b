#pragma once
// A primal-dual interior-point method for sparse nonlinear least squares
// within bounds: minimise f(x) = sum_k r_k(x)^2 subject to lower <= x <= upper,
// each residual r_k a function of a few of the variables. It is IPOPT's
// algorithm (Waechter and Biegler 2006, "On the implementation of an
// interior-point filter line-search algorithm for large-scale nonlinear
// programming") specialised to a problem with bounds and no other
// constraints, where the filter reduces to an Armijo search on the barrier
// function and the Newton system to (H + Sigma) dx = -grad phi_mu with H the
// Gauss-Newton Hessian 2 J^T J (positive semi-definite) and Sigma the
// bounds' positive diagonal: a sparse Cholesky factorisation (Eigen's, its
// fill-reducing ordering and symbolic analysis done once per solve) with no
// inertia to correct. Monotone barrier updates (IPOPT's mu_strategy
// monotone, the Fiacco-McCormick rule), fraction-to-the-boundary steps for
// primal and dual variables, IPOPT's default constants and its scaled
// optimality error as the stopping test. A variable whose bounds are equal
// is fixed there (IPOPT's make_parameter).
//
// Why not IPOPT itself: the racing line solves hundreds of these problems
// a lap, each of 20 to 400 variables; IPOPT 3.11 with Debian's MUMPS spent
// about a millisecond an iteration in the sparse solver's per-call set-up
// and in its own CPU-time accounting (getrusage twice per timed task),
// where the banded factorisation itself takes microseconds. The test
// checks this solver against IPOPT on the same problems.
#include <cstddef>
#include <string>
#include <vector>

namespace paddock::planning {

// the residuals: r_k depends on the variables variables(k)[0..arity(k))
class SparseLeastSquares {
 public:
  static constexpr std::size_t kMaxArity = 8;

  virtual ~SparseLeastSquares() = default;
  virtual std::size_t residuals() const = 0;
  virtual std::size_t arity(std::size_t k) const = 0;
  virtual const int* variables(std::size_t k) const = 0;
  // r_k at x (all the variables), and when jacobian is not null its partial
  // derivatives with respect to variables(k), in that order
  virtual double residual(std::size_t k, const double* x, double* jacobian) const = 0;
};

struct InteriorPointOptions {
  // the scaled optimality error (dual infeasibility and complementarity,
  // IPOPT's E_0) at which the solve stops
  double tol = 1e-10;
  int max_iterations = 300;
};

struct InteriorPointResult {
  // Acceptable: IPOPT's "solved to an acceptable level", the error within
  // 1e-6 for 15 iterations in a row without reaching the tolerance
  enum class Status { Converged, Acceptable, MaxIterations, Stalled, Failed };
  Status status = Status::Failed;
  int iterations = 0;   // Newton steps taken
  double cost = 0.0;    // f at the returned x
  double error = 0.0;   // the scaled optimality error there
  std::string reason;   // why it failed or stalled

  // a point within the bounds no worse than the start: the solve may stop
  // short of the tolerance (iterations spent, or no step the line search
  // accepts, which rounding causes once the error is near the tolerance)
  bool usable() const { return status != Status::Failed; }
};

// minimises from x (moved inside the bounds first); x returns the solution,
// within the bounds. Sizes that differ, lower > upper, a non-finite bound or
// start, or a residual that is not finite at the start give Failed and
// leave x unchanged.
InteriorPointResult minimise_within_bounds(const SparseLeastSquares& problem, const std::vector<double>& lower,
                                           const std::vector<double>& upper, std::vector<double>& x,
                                           const InteriorPointOptions& options = {});

}  // namespace paddock::planning
