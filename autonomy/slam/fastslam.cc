#include "autonomy/slam/fastslam.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "autonomy/common/fast_math.h"

namespace paddock::slam {

namespace {

using Eigen::Matrix2d;
using Eigen::Matrix3d;
using Eigen::Vector2d;
using Eigen::Vector3d;
using Matrix23 = Eigen::Matrix<double, 2, 3>;

constexpr double kLog2Pi = 1.8378770664093453;  // log(2 pi)
constexpr double kMaxDelta = 1000.0;             // m: more in one predict is no odometry

// wrap_angle without its fmod for the angles already in [-pi, pi) (nearly
// all), and wrap_angle's result without its fmod for those within a turn of
// it (a bearing difference across +-pi: ~10 per particle and frame): there
// fmod(t, 2 pi) is t or t - 2 pi, both exact (Sterbenz), as fmod is
double wrap(double a) {
  if (a >= -kPi && a < kPi) return a;
  const double turn = 2.0 * kPi;
  double t = a + kPi;
  if (t >= turn && t < 2.0 * turn) {
    t -= turn;
  } else if (!(t > -turn && t < turn)) {
    return wrap_angle(a);
  }
  if (t < 0.0) t += turn;  // as wrap_angle, from here on
  return t - kPi;
}

// h(s, m) and its Jacobians (see the header)
struct Predicted {
  Vector2d z;
  Matrix2d Hm;
  Matrix23 Hs;
};

// (inlined into its three callers: ~100 calls a particle and frame, and
// update_landmarks then computes no H_s; 3 % of the update bench)
[[gnu::always_inline]] inline Predicted predict_measurement(const Pose2& s, Vec2 m) {
  const double dx = m.x - s.x, dy = m.y - s.y;
  const double q = std::max(dx * dx + dy * dy, 1e-12);
  const double r = std::sqrt(q);
  // one division: the Jacobians' 1/r and 1/q from it
  const double inv_r = 1.0 / r, inv_q = inv_r * inv_r;
  const double cx = dx * inv_r, cy = dy * inv_r, ex = dx * inv_q, ey = dy * inv_q;
  Predicted p;
  p.z = {r, wrap(fast_atan2(dy, dx) - s.yaw)};
  p.Hm << cx, cy, -ey, ex;
  p.Hs << -cx, -cy, 0.0, ey, -ex, -1.0;
  return p;
}

// H_m alone, as predict_measurement computes it
Matrix2d landmark_jacobian(const Pose2& s, Vec2 m) {
  const double dx = m.x - s.x, dy = m.y - s.y;
  const double q = std::max(dx * dx + dy * dy, 1e-12);
  const double r = std::sqrt(q);
  Matrix2d Hm;
  Hm << dx / r, dy / r, -dy / q, dx / q;
  return Hm;
}

Vector2d innovation(const Vector2d& z, const Vector2d& zhat) {
  return {z(0) - zhat(0), wrap(z(1) - zhat(1))};
}

// N(nu; 0, S) in its parts: the squared Mahalanobis distance and det S
struct GaussTerms {
  double d2, det;
};

GaussTerms gauss_terms(const Vector2d& nu, const Matrix2d& S) {
  const double det = S.determinant();
  const Vector2d Sinv_nu = S.inverse() * nu;
  return {nu.dot(Sinv_nu), det};
}

double log_gauss(const GaussTerms& g) { return -0.5 * g.d2 - kLog2Pi - 0.5 * std::log(g.det); }

// log_gauss(g) >= level, known without its log: det < 2^e for det's binary
// exponent e, so log N > -d2 / 2 - log(2 pi) - e log(2) / 2; a margin of
// 1e-6, far above the rounding of either side. False: the log must decide.
bool surely_above(const GaussTerms& g, double level) {
  if (!(g.det > 0.0 && g.det <= std::numeric_limits<double>::max() && g.d2 < std::numeric_limits<double>::max())) return false;
  std::uint64_t bits;
  std::memcpy(&bits, &g.det, sizeof bits);
  const int e = static_cast<int>((bits >> 52) & 0x7ff) - 1022;  // det in [2^(e-1), 2^e) (below, if subnormal)
  constexpr double kLn2 = 0.6931471805599453;
  return -0.5 * g.d2 - kLog2Pi - 0.5 * kLn2 * static_cast<double>(e) >= level + 1e-6;
}

// log N(nu; 0, S)
double log_gauss(const Vector2d& nu, const Matrix2d& S) { return log_gauss(gauss_terms(nu, S)); }

// the squared Mahalanobis distance alone (the gate, before any log)
double mahalanobis2(const Vector2d& nu, const Matrix2d& S) {
  // 2x2 inverse by hand: [d -b; -c a] / det
  const double det = S(0, 0) * S(1, 1) - S(0, 1) * S(1, 0);
  return (S(1, 1) * nu(0) * nu(0) - (S(0, 1) + S(1, 0)) * nu(0) * nu(1) + S(0, 0) * nu(1) * nu(1)) / det;
}

}  // namespace

ConeColor Landmark::color() const { return most_voted(votes); }

void FastSlam::Bounds::cover(Vec2 m) {
  lo_x = std::min(lo_x, m.x);
  lo_y = std::min(lo_y, m.y);
  hi_x = std::max(hi_x, m.x);
  hi_y = std::max(hi_y, m.y);
}

double FastSlam::Bounds::squared_distance(Vec2 c) const {
  // per axis the nearest edge's difference, computed as m - c is for a mean
  // m in the box (fl(m - c) >= fl(lo - c) for m >= lo: the bound is exact)
  const double lx = lo_x - c.x, hx = hi_x - c.x;
  const double ly = lo_y - c.y, hy = hi_y - c.y;
  const double dx = lx > 0.0 ? lx : (hx < 0.0 ? hx : 0.0);
  const double dy = ly > 0.0 ? ly : (hy < 0.0 ? hy : 0.0);
  return dx * dx + dy * dy;
}

// (inline: ~70 calls a particle and frame; the clone out of line)
inline FastSlam::Slot& FastSlam::Particle::mutable_slot(int i) {
  BlockRef& ref = blocks[static_cast<std::size_t>(i / kLandmarkBlock)];
  LiveBlock& lb = live[static_cast<std::size_t>(ref.live)];
  if (sharing_fixed ? lb.shared : lb.block.use_count() > 1) clone(ref, lb);
  return ref.block->slots[i % kLandmarkBlock];
}

void FastSlam::Particle::clone(BlockRef& ref, LiveBlock& lb) {
  lb.block = std::make_shared<Block>(*lb.block);  // copy on write
  ref.block = lb.block.get();
  lb.shared = false;
}

int FastSlam::Particle::add(const Slot& s) {
  const int i = size++;
  const int b = i / kLandmarkBlock;
  if (b == static_cast<int>(blocks.size())) blocks.push_back({nullptr, -1});
  BlockRef& ref = blocks[static_cast<std::size_t>(b)];
  if (!ref.block) {
    // a new block, or the last one again after its slots so far all died
    live.push_back({std::make_shared<Block>(), b, 0u, Bounds{}});
    ref = {live.back().block.get(), static_cast<int>(live.size()) - 1};
  }
  mutable_slot(i) = s;
  LiveBlock& lb = live.back();  // the last block is the last live one
  lb.alive |= 1u << (i % kLandmarkBlock);
  lb.bounds.cover(s.lm.mean);
  return i;
}

void FastSlam::Particle::sweep() {
  // nothing reads a dead slot: a block of dead ones need not be kept (or
  // copied by a resample)
  std::size_t n = 0;
  for (LiveBlock& lb : live) {
    BlockRef& ref = blocks[static_cast<std::size_t>(lb.number)];
    if (lb.alive == 0) {
      ref = {nullptr, -1};
      continue;
    }
    ref.live = static_cast<int>(n);
    if (&live[n] != &lb) live[n] = std::move(lb);
    ++n;
  }
  live.resize(n);
}

FastSlam::FastSlam(const FastSlamParams& p, std::uint64_t seed)
    : params_(params::require_valid(p, "FastSlamParams")), rng_(seed), workers_(params_.threads) {
  reset(Pose2{});
}

void FastSlam::reset(const Pose2& pose) {
  particles_.assign(static_cast<std::size_t>(params_.particles), Particle{});
  const double w = 1.0 / params_.particles;
  for (Particle& p : particles_) {
    p.pose = {pose.x, pose.y, wrap_angle(pose.yaw)};
    p.weight = w;
    p.copy_of = 0;  // all alike
  }
  best_ = 0;
  neff_ = params_.particles;
  anchor_ = {particles_[0].pose, Matrix3d::Zero(), Matrix3d::Zero()};
  cov_.setZero();
}

void FastSlam::predict(const Pose2& delta) {
  // not odometry: a value that is not finite, or a jump no car makes between two frames
  if (!finite(delta) || std::hypot(delta.x, delta.y) > kMaxDelta || std::abs(delta.yaw) > 2.0 * kPi) {
    ++rejected_;
    return;
  }
  // the odometry's noise on this step's delta (see the header)
  const double dist = std::hypot(delta.x, delta.y);
  const double sxy = params_.motion_std_xy_per_m * dist;
  const double syaw = params_.motion_std_yaw_per_m * dist + params_.motion_std_yaw_per_rad * std::abs(delta.yaw);
  const Vector3d q(sxy * sxy, sxy * sxy, syaw * syaw);
  for (Particle& p : particles_) {
    // P' = F P F^T + G Q G^T about the pre-step yaw
    const double c = std::cos(p.pose.yaw), s = std::sin(p.pose.yaw);
    const Vec2 rd{c * delta.x - s * delta.y, s * delta.x + c * delta.y};
    Matrix3d F = Matrix3d::Identity();
    F(0, 2) = -rd.y;
    F(1, 2) = rd.x;
    Matrix3d G = Matrix3d::Identity();
    G(0, 0) = c;
    G(0, 1) = -s;
    G(1, 0) = s;
    G(1, 1) = c;
    p.P = F * p.P * F.transpose() + G * q.asDiagonal() * G.transpose();
    // compose(p.pose, delta) with the rotation above: compose is position +
    // rotate(d, yaw), the same products and sums as rd's (one sin and cos of
    // the yaw a particle, not two); the yaw wrapped by wrap_angle as there
    // (not wrap(): in range, wrap_angle rounds through a + pi - pi)
    p.pose = {p.pose.x + rd.x, p.pose.y + rd.y, wrap_angle(p.pose.yaw + delta.yaw)};
  }
}

Vector3d FastSlam::standard_normals() {
  std::normal_distribution<double> n01(0.0, 1.0);
  return Vector3d(n01(rng_), n01(rng_), n01(rng_));
}

Pose2 FastSlam::sample_pose(const Pose2& mean, const Matrix3d& cov, const Vector3d& n) {
  Vector3d d;
  Eigen::LLT<Matrix3d> llt(cov);
  if (llt.info() == Eigen::Success) {
    d = llt.matrixL() * n;
  } else {
    // positive semi-definite (exact odometry: zero): by its eigenvectors
    Eigen::SelfAdjointEigenSolver<Matrix3d> es(cov);
    const Vector3d sd = es.eigenvalues().cwiseMax(0.0).cwiseSqrt();
    d = es.eigenvectors() * sd.cwiseProduct(n);
  }
  return {mean.x + d(0), mean.y + d(1), wrap(mean.yaw + d(2))};
}

void FastSlam::prepare(const std::vector<Observation>& obs) {
  Frame& f = frame_;
  f.z.clear();
  f.R.clear();
  f.obs.clear();
  for (const Observation& o : obs) {
    const double r = norm(o.position);
    if (!finite(o.position) || !(r >= params_.min_range) || static_cast<std::int64_t>(f.obs.size()) >= kIdsPerUpdate) {
      ++rejected_;
      continue;
    }
    const double sr = params_.range_std + params_.range_std_per_m * r;
    f.z.emplace_back(r, angle_of(o.position));
    f.R.push_back(Vector2d(sr * sr, params_.bearing_std * params_.bearing_std).asDiagonal());
    f.obs.push_back(&o);
  }
  f.by_x.resize(f.obs.size());
  for (std::size_t k = 0; k < f.by_x.size(); ++k) f.by_x[k] = static_cast<int>(k);
  std::sort(f.by_x.begin(), f.by_x.end(), [&f](int a, int b) {
    const double xa = f.obs[static_cast<std::size_t>(a)]->position.x, xb = f.obs[static_cast<std::size_t>(b)]->position.x;
    return xa < xb || (xa == xb && a < b);
  });
  f.sorted_x.clear();
  f.sorted_y.clear();
  for (int k : f.by_x) {
    f.sorted_x.push_back(f.obs[static_cast<std::size_t>(k)]->position.x);
    f.sorted_y.push_back(f.obs[static_cast<std::size_t>(k)]->position.y);
  }
}

void FastSlam::update(const std::vector<Observation>& obs, const std::vector<float>& free_range) {
  // (a boundary with no obstacle in it hides nothing: skipped)
  free_range_ = std::any_of(free_range.begin(), free_range.end(), [](float f) { return std::isfinite(f); }) ? &free_range : nullptr;
  prepare(obs);

  // each particle: sample its pose, associate, update its map; log-likelihoods
  const std::size_t n = particles_.size();
  std::vector<double>& ll = log_lik_;
  ll.assign(n, 0.0);
  frame_ids_.resize(n);
  // the particles' draws in their order, from the one generator, before the
  // particles are split between the threads (the same stream however many)
  draws_.resize(n);
  for (Vector3d& d : draws_) d = standard_normals();
  const int parts = static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(workers_.threads()), n));
  scratch_.resize(static_cast<std::size_t>(workers_.threads()));
  if (parts > 1) {
    // which blocks are shared, fixed now for the update (no reference is
    // taken during one: the counts only fall)
    for (Particle& p : particles_) {
      p.sharing_fixed = true;
      for (LiveBlock& lb : p.live) lb.shared = lb.block.use_count() > 1;
    }
  }
  workers_.run([&](int part) {
    if (part >= parts) return;
    const auto [begin, end] = Workers::range(n, parts, part);
    Scratch& w = scratch_[static_cast<std::size_t>(part)];
    for (std::size_t i = begin; i < end; ++i) {
      // a copy of the previous particle reuses its association: within a part
      const int parent = particles_[i].copy_of;
      update_particle(particles_[i], frame_, parent >= 0 && i > begin && particles_[i - 1].copy_of == parent, ll[i],
                      frame_ids_[i], draws_[i], w);
    }
  });
  for (Particle& p : particles_) {
    p.copy_of = -1;  // each drew its own pose
    p.sharing_fixed = false;
  }

  // reweight (in logs, about the largest, against underflow) and normalise
  const double top = *std::max_element(ll.begin(), ll.end());
  double sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    particles_[i].weight *= std::exp(ll[i] - top);
    sum += particles_[i].weight;
  }
  if (!(sum > 0.0) || !std::isfinite(sum)) {
    // every weight underflowed: start again from equal weights
    for (Particle& p : particles_) p.weight = 1.0 / static_cast<double>(n);
  } else {
    for (Particle& p : particles_) p.weight /= sum;
  }
  double sum2 = 0.0;
  best_ = 0;
  for (std::size_t i = 0; i < n; ++i) {
    sum2 += particles_[i].weight * particles_[i].weight;
    if (particles_[i].weight > particles_[static_cast<std::size_t>(best_)].weight) best_ = static_cast<int>(i);
  }
  neff_ = 1.0 / sum2;
  best_sightings_.clear();
  const std::vector<std::int64_t>& ids = frame_ids_[static_cast<std::size_t>(best_)];
  for (std::size_t k = 0; k < ids.size(); ++k) best_sightings_.emplace_back(ids[k], frame_.obs[k]->position);
  ++updates_;
  if (neff_ < params_.resample_neff_ratio * static_cast<double>(n)) resample();
  update_covariance();
}

void FastSlam::gather_near(const Particle& p, Scratch& w) {
  // the landmarks near enough to matter this frame (view, or an
  // observation's reach): their indices, and their positions in contiguous
  // arrays for the association's search
  const FastSlamParams& pr = params_;
  const double reach = std::max(pr.view_range, 0.0) + pr.search_radius;
  w.near.clear();
  w.near_live.clear();
  w.near_x.clear();
  w.near_y.clear();
  const double under2 = 0.25 * pr.min_range * pr.min_range;
  // the blocks in reach (none of the others' landmarks is: most blocks, the
  // car meets them in order); their alive slots' means and covariances asked
  // of memory all at once: a particle's blocks are mostly its own copies,
  // rarely in cache, and one after another they would cost a miss each
  w.in_reach.clear();
  for (std::size_t l = 0; l < p.live.size(); ++l) {
    const LiveBlock& lb = p.live[l];
    if (lb.bounds.squared_distance(p.pose.position()) >= reach * reach) continue;
    w.in_reach.push_back(static_cast<int>(l));
    const Block& block = *lb.block;
    for (std::uint32_t alive = lb.alive; alive != 0; alive &= alive - 1) {
      const char* slot = reinterpret_cast<const char*>(&block.slots[static_cast<std::size_t>(__builtin_ctz(alive))]);
      __builtin_prefetch(slot);
      __builtin_prefetch(slot + sizeof(Vec2) + sizeof(Eigen::Matrix2d) - 1);
    }
  }
  for (int l : w.in_reach) {
    const LiveBlock& lb = p.live[static_cast<std::size_t>(l)];
    // its alive slots, lowest first (the order of the indices)
    const Block& block = *lb.block;
    for (std::uint32_t alive = lb.alive; alive != 0; alive &= alive - 1) {
      const int j = __builtin_ctz(alive);
      const Slot& s = block.slots[static_cast<std::size_t>(j)];
      const double d2 = squared_norm(s.lm.mean - p.pose.position());
      // (one under the car has no stable bearing: neither scored nor expected)
      if (d2 < reach * reach && d2 > under2) {
        w.near.push_back(lb.number * kLandmarkBlock + j);
        w.near_live.push_back(l);
        w.near_x.push_back(s.lm.mean.x);
        w.near_y.push_back(s.lm.mean.y);
      }
    }
  }
}

void FastSlam::find_candidates(const Particle& p, const Frame& f, Scratch& w) {
  // each near landmark against the observations landing within
  // search_radius of it (at s^ for 2.0, at the sampled pose for 1.0),
  // scored by likelihood within the gate and above the new-landmark one
  const FastSlamParams& pr = params_;
  const bool v2 = pr.fastslam_version == 2;
  const double log_p0 = std::log(pr.new_landmark_likelihood);
  const double cy = std::cos(p.pose.yaw), sy = std::sin(p.pose.yaw);
  const std::size_t m = f.z.size();
  w.land_x.resize(m);
  w.land_y.resize(m);
  for (std::size_t k = 0; k < m; ++k) {
    const Vec2 o = f.obs[k]->position;
    w.land_x[k] = p.pose.x + cy * o.x - sy * o.y;
    w.land_y[k] = p.pose.y + sy * o.x + cy * o.y;
  }
  // the observations to try, by their position in the base frame: x, then
  // y within the radius of the landmark's there, and a margin far above the
  // rounding of the two frames (the distance test itself is the world frame's)
  const double band = pr.search_radius + 1e-9 * (1.0 + pr.search_radius + std::abs(p.pose.x) + std::abs(p.pose.y));
  const double r2 = pr.search_radius * pr.search_radius;
  const Matrix2d assoc = pr.association_std * pr.association_std * Matrix2d::Identity();
  w.cands.clear();
  for (std::size_t j = 0; j < w.near.size(); ++j) {
    const double dx = w.near_x[j] - p.pose.x, dy = w.near_y[j] - p.pose.y;
    const double bx = cy * dx + sy * dy, by = cy * dy - sy * dx;
    std::size_t i = static_cast<std::size_t>(std::lower_bound(f.sorted_x.begin(), f.sorted_x.end(), bx - band) - f.sorted_x.begin());
    // h, H_m C H_m^T and H_s P H_s^T: the landmark's, whichever observation
    bool predicted = false;
    Predicted h;
    Matrix2d HCH, HPH;
    for (; i < f.sorted_x.size() && f.sorted_x[i] <= bx + band; ++i) {
      if (std::abs(f.sorted_y[i] - by) > band) continue;
      const std::size_t k = static_cast<std::size_t>(f.by_x[i]);
      const double ex = w.near_x[j] - w.land_x[k], ey = w.near_y[j] - w.land_y[k];
      if (ex * ex + ey * ey > r2) continue;
      if (!predicted) {
        const Slot& s = p.slot(w.near[j]);
        h = predict_measurement(p.pose, s.lm.mean);
        HCH = h.Hm * (s.lm.cov + assoc) * h.Hm.transpose();
        if (v2) HPH = h.Hs * p.P * h.Hs.transpose();
        predicted = true;
      }
      Matrix2d Z = HCH + f.R[k];
      if (v2) Z += HPH;
      const Vector2d nu = innovation(f.z[k], h.z);
      if (!(mahalanobis2(nu, Z) <= pr.association_gate)) continue;
      const GaussTerms g = gauss_terms(nu, Z);
      Candidate c{0.0, g.d2, g.det, static_cast<int>(k), static_cast<int>(j), false};
      if (!surely_above(g, log_p0)) {
        // not sure to be likelier than a new landmark: the log decides
        c.ll = log_gauss(g);
        c.scored = true;
        if (!(c.ll >= log_p0)) continue;
      }
      w.cands.push_back(c);
    }
  }
}

const std::vector<int>& FastSlam::associate(const Particle& p, const Frame& f, Scratch& w) {
  // maximum likelihood per observation, one observation per landmark
  // (mutual exclusion): the candidates best first (ties: the earlier
  // observation, then landmark; w.near is in index order). A candidate alone
  // on its observation and on its landmark (most) is taken whatever its
  // likelihood; only its rivals need ranking, their own among them.
  find_candidates(p, f, w);
  const std::size_t m = f.z.size();
  w.cands_per_obs.assign(m, 0);
  w.cands_per_near.assign(w.near.size(), 0);
  for (const Candidate& c : w.cands) {
    ++w.cands_per_obs[static_cast<std::size_t>(c.obs)];
    ++w.cands_per_near[static_cast<std::size_t>(c.near)];
  }
  w.match.assign(m, -1);
  w.near_taken.assign(w.near.size(), 0);
  w.rivals.clear();
  for (Candidate& c : w.cands) {
    if (w.cands_per_obs[static_cast<std::size_t>(c.obs)] == 1 && w.cands_per_near[static_cast<std::size_t>(c.near)] == 1) {
      w.match[static_cast<std::size_t>(c.obs)] = c.near;
      w.near_taken[static_cast<std::size_t>(c.near)] = 1;
      continue;
    }
    if (!c.scored) c.ll = log_gauss(GaussTerms{c.d2, c.det});
    w.rivals.push_back(c);
  }
  std::sort(w.rivals.begin(), w.rivals.end(), [](const Candidate& a, const Candidate& b) {
    if (a.ll != b.ll) return a.ll > b.ll;
    if (a.obs != b.obs) return a.obs < b.obs;
    return a.near < b.near;
  });
  for (const Candidate& c : w.rivals) {
    int& match = w.match[static_cast<std::size_t>(c.obs)];
    char& taken = w.near_taken[static_cast<std::size_t>(c.near)];
    if (match >= 0 || taken) continue;
    match = c.near;
    taken = 1;
  }
  return w.match;
}

void FastSlam::propose(const Particle& p, const Frame& f, const std::vector<int>& match, Scratch& w) {
  // FastSLAM 2.0: fold the associated observations into the pose's proposal,
  // weigh by each one's likelihood given the ones before (into w.proposal)
  Vector3d mu(p.pose.x, p.pose.y, p.pose.yaw);
  Matrix3d Sigma = p.P;
  double log_lik = 0.0;
  for (std::size_t k = 0; k < f.z.size(); ++k) {
    if (match[k] < 0) continue;
    const Slot& s = p.slot(w.near[static_cast<std::size_t>(match[k])]);
    const Pose2 at{mu(0), mu(1), mu(2)};
    const Predicted h = predict_measurement(at, s.lm.mean);
    const Matrix2d Z = h.Hs * Sigma * h.Hs.transpose() + h.Hm * s.lm.cov * h.Hm.transpose() + f.R[k];
    const Vector2d nu = innovation(f.z[k], h.z);
    // Z^-1 once for the weight and the gain (gauss_terms' determinant is the
    // inverse's own: the same products)
    const Matrix2d Zinv = Z.inverse();
    log_lik += log_gauss(GaussTerms{nu.dot(Zinv * nu), Z.determinant()});
    const Eigen::Matrix<double, 3, 2> Ks = Sigma * h.Hs.transpose() * Zinv;
    mu += Ks * nu;
    mu(2) = wrap(mu(2));
    Sigma -= Ks * Z * Ks.transpose();
    Sigma = 0.5 * (Sigma + Sigma.transpose());
  }
  w.proposal = {{mu(0), mu(1), mu(2)}, Sigma, log_lik};
}

void FastSlam::update_landmarks(Particle& p, const Frame& f, const std::vector<int>& match, double& log_lik,
                                Scratch& w) {
  // the associated landmarks' EKFs at the sampled pose (1.0 weighs here)
  const FastSlamParams& pr = params_;
  for (std::size_t k = 0; k < f.z.size(); ++k) {
    if (match[k] < 0) continue;
    const Observation& o = *f.obs[k];
    const std::size_t j = static_cast<std::size_t>(match[k]);
    Slot& s = p.mutable_slot(w.near[j]);
    Landmark& lm = s.lm;
    const Predicted h = predict_measurement(p.pose, lm.mean);
    const Matrix2d S = h.Hm * lm.cov * h.Hm.transpose() + f.R[k];
    const Vector2d nu = innovation(f.z[k], h.z);
    if (pr.fastslam_version != 2) log_lik += log_gauss(nu, S);
    const Matrix2d K = lm.cov * h.Hm.transpose() * S.inverse();
    const Vector2d dm = K * nu;
    lm.mean += Vec2{dm(0), dm(1)};
    p.live[static_cast<std::size_t>(w.near_live[j])].bounds.cover(lm.mean);
    lm.cov = (Matrix2d::Identity() - K * h.Hm) * lm.cov;
    lm.cov = 0.5 * (lm.cov + lm.cov.transpose());
    ++lm.sightings;
    lm.votes[static_cast<std::size_t>(o.color)] += o.colour_from_camera ? pr.camera_vote_weight : 1.0;
    if (lm.sightings >= pr.confirm_sightings) lm.confirmed = true;
    s.misses = 0;
  }
}

void FastSlam::expect_and_remove(Particle& p, double cy, double sy, Scratch& w) {
  // expectations and removal of the landmarks that were there before this frame
  // (in view: |b| < view_range and |bearing| < view_half_fov <=> b_x > |b| cos(view_half_fov))
  const FastSlamParams& pr = params_;
  const double cos_fov = std::cos(pr.view_half_fov);
  bool died = false;
  for (std::size_t j = 0; j < w.near.size(); ++j) {
    const int i = w.near[j];
    const bool seen = w.near_taken[j] != 0;
    if (!seen) {
      // (its mean is still w.near's copy: only the seen ones have moved)
      const Vec2 d = Vec2{w.near_x[j], w.near_y[j]} - p.pose.position();
      const Vec2 b{cy * d.x + sy * d.y, -sy * d.x + cy * d.y};
      const double b2 = squared_norm(b);
      const bool in_view = b2 < pr.view_range * pr.view_range && b.x > std::sqrt(b2) * cos_fov;
      if (!in_view) continue;
      // hidden behind an obstacle in its bearing: not expected either
      if (free_range_ != nullptr) {
        const std::vector<float>& fr = *free_range_;
        const float edge = fr[hal::free_range_bin(fast_atan2(b.y, b.x), fr.size())];
        if (std::sqrt(b2) > static_cast<double>(edge) + pr.occlusion_margin) continue;
      }
    }
    Slot& s = p.mutable_slot(i);
    ++s.lm.expected;
    if (!seen) ++s.misses;
    const bool rare = s.lm.expected >= pr.remove_min_expected &&
                      static_cast<double>(s.lm.sightings) < pr.remove_ratio * static_cast<double>(s.lm.expected);
    const int misses = s.lm.confirmed ? pr.remove_misses : pr.remove_tentative_misses;
    if (rare || s.misses >= misses) {
      p.live[static_cast<std::size_t>(w.near_live[j])].alive &= ~(1u << (i % kLandmarkBlock));
      died = true;
    }
  }
  if (died) p.sweep();
}

void FastSlam::add_new_landmarks(Particle& p, const Frame& f, const std::vector<int>& match, double cy, double sy,
                                 double& log_lik, std::vector<std::int64_t>& ids) {
  // observations without a landmark start tentative ones
  const FastSlamParams& pr = params_;
  const double log_p0 = std::log(pr.new_landmark_likelihood);
  for (std::size_t k = 0; k < f.z.size(); ++k) {
    if (match[k] >= 0) continue;
    const Observation& o = *f.obs[k];
    log_lik += log_p0;
    Slot s;
    s.lm.id = updates_ * kIdsPerUpdate + static_cast<std::int64_t>(k);
    ids[k] = s.lm.id;
    s.lm.mean = {p.pose.x + cy * o.position.x - sy * o.position.y, p.pose.y + sy * o.position.x + cy * o.position.y};
    const Matrix2d Hinv = landmark_jacobian(p.pose, s.lm.mean).inverse();
    s.lm.cov = Hinv * f.R[k] * Hinv.transpose();
    s.lm.sightings = 1;
    s.lm.expected = 1;
    s.lm.votes[static_cast<std::size_t>(o.color)] += o.colour_from_camera ? pr.camera_vote_weight : 1.0;
    s.lm.confirmed = s.lm.sightings >= pr.confirm_sightings;
    p.add(s);
  }
}

void FastSlam::update_particle(Particle& p, const Frame& f, bool copy_of_previous, double& log_lik,
                               std::vector<std::int64_t>& ids, const Eigen::Vector3d& draw, Scratch& w) {
  const bool v2 = params_.fastslam_version == 2;
  // FastSLAM 1.0: the pose from the motion model before anything else
  if (!v2) {
    p.pose = sample_pose(p.pose, p.P, draw);
    p.P.setZero();
  }
  // (2.0) an unchanged copy of the particle before it finds the same
  // landmarks near, the same association and the same proposal
  if (!(v2 && copy_of_previous)) {
    gather_near(p, w);
    associate(p, f, w);
    if (v2) propose(p, f, w.match, w);
  }
  if (v2) {
    log_lik += w.proposal.log_lik;
    p.pose = sample_pose(w.proposal.mean, w.proposal.cov, draw);
    p.P.setZero();
  }
  // the associated landmarks' ids, before a removal may let their block go
  ids.assign(w.match.size(), -1);
  for (std::size_t k = 0; k < w.match.size(); ++k)
    if (w.match[k] >= 0) ids[k] = p.slot(w.near[static_cast<std::size_t>(w.match[k])]).lm.id;  // match: positions in near
  update_landmarks(p, f, w.match, log_lik, w);
  // the sampled pose's rotation, for both (its yaw no longer changes)
  const double cy = std::cos(p.pose.yaw), sy = std::sin(p.pose.yaw);
  expect_and_remove(p, cy, sy, w);
  add_new_landmarks(p, f, w.match, cy, sy, log_lik, ids);
}

void FastSlam::resample() {
  // low variance: one uniform draw, N equally spaced pointers into the cumulative weights
  const std::size_t n = particles_.size();
  const double step = 1.0 / static_cast<double>(n);
  std::uniform_real_distribution<double> u01(0.0, step);
  const double r = u01(rng_);
  picks_.resize(n);
  int new_best = -1;
  double c = particles_[0].weight;
  std::size_t i = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const double u = r + static_cast<double>(k) * step;
    while (u > c && i + 1 < n) c += particles_[++i].weight;
    if (new_best < 0 && static_cast<int>(i) == best_) new_best = static_cast<int>(k);
    picks_[k] = static_cast<int>(i);
  }
  if (new_best < 0) {
    // the best particle always survives (its weight >= 1/N); keep it if rounding says otherwise
    picks_[0] = best_;
    new_best = 0;
  }
  // into the spare set (its vectors keep their capacity): a parent's copies
  // are consecutive, its last one takes it over (no copy of its block
  // pointers, no count of references up and down again)
  spare_.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    Particle& parent = particles_[static_cast<std::size_t>(picks_[k])];
    if (k + 1 == n || picks_[k + 1] != picks_[k]) {
      // a swap, not a move: the parent keeps the spare's vectors, and with
      // them their capacity for the next resample's copies
      std::swap(spare_[k], parent);
    } else {
      spare_[k] = parent;
    }
    spare_[k].weight = step;
    spare_[k].copy_of = picks_[k];
  }
  particles_.swap(spare_);
  // the old set lets go of its blocks (a block held there would be cloned
  // on its next write for nothing)
  for (Particle& old : spare_) {
    old.blocks.clear();
    old.live.clear();
  }
  best_ = new_best;
  ++resamples_;
}

void FastSlam::reanchor(const Pose2& pose, const std::vector<std::pair<std::int64_t, Vec2>>& landmarks,
                        std::int64_t forget_from, int particles) {
  if (!finite(pose)) {
    ++rejected_;
    return;
  }
  const int count = particles > 0 ? particles : params_.particles;
  Particle best = particles_[static_cast<std::size_t>(best_)];
  best.pose = pose;
  best.P.setZero();
  best.weight = 1.0 / static_cast<double>(count);
  best.copy_of = -1;
  // id -> position, then one pass over the particle's alive slots
  std::vector<std::pair<std::int64_t, Vec2>> sorted = landmarks;
  std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  bool died = false;
  for (LiveBlock& lb : best.live) {
    for (std::uint32_t alive = lb.alive; alive != 0; alive &= alive - 1) {
      const int j = __builtin_ctz(alive);
      const int i = lb.number * kLandmarkBlock + j;
      const std::int64_t id = best.slot(i).lm.id;
      if (id / kIdsPerUpdate >= forget_from) {
        lb.alive &= ~(1u << j);
        died = true;
        continue;
      }
      const auto it = std::lower_bound(sorted.begin(), sorted.end(), id,
                                       [](const auto& a, std::int64_t k) { return a.first < k; });
      if (it == sorted.end() || it->first != id || !finite(it->second)) continue;
      best.mutable_slot(i).lm.mean = it->second;
      lb.bounds.cover(it->second);  // the box grows to the moved mean (a bound, never too small)
    }
  }
  if (died) best.sweep();
  particles_.resize(static_cast<std::size_t>(count));
  for (Particle& p : particles_) p = best;
  best_ = 0;
}

Pose2 FastSlam::pose() const {
  const Pose2& p = particles_[static_cast<std::size_t>(best_)].pose;
  return p;
}

std::vector<Landmark> FastSlam::landmarks(bool confirmed_only) const {
  const Particle& p = particles_[static_cast<std::size_t>(best_)];
  std::vector<Landmark> out;
  for (const LiveBlock& lb : p.live) {
    for (std::uint32_t alive = lb.alive; alive != 0; alive &= alive - 1) {
      const Slot& s = lb.block->slots[static_cast<std::size_t>(__builtin_ctz(alive))];
      if (s.lm.confirmed || !confirmed_only) out.push_back(s.lm);
    }
  }
  return out;
}

std::vector<Landmark> FastSlam::map() const { return landmarks(true); }
std::vector<Landmark> FastSlam::all_landmarks() const { return landmarks(false); }

Pose2 FastSlam::mean_pose() const {
  const double ref = particles_[static_cast<std::size_t>(best_)].pose.yaw;
  double x = 0.0, y = 0.0, dyaw = 0.0;
  for (const Particle& p : particles_) {
    x += p.weight * p.pose.x;
    y += p.weight * p.pose.y;
    dyaw += p.weight * wrap_angle(p.pose.yaw - ref);
  }
  return {x, y, wrap_angle(ref + dyaw)};
}

Matrix3d FastSlam::cloud_covariance() const { return cloud_covariance(mean_pose()); }

Matrix3d FastSlam::cloud_covariance(const Pose2& mean) const {
  Matrix3d c = Matrix3d::Zero();
  for (const Particle& p : particles_) {
    const Vector3d e(p.pose.x - mean.x, p.pose.y - mean.y, wrap_angle(p.pose.yaw - mean.yaw));
    c += p.weight * (p.P + e * e.transpose());
  }
  return c;
}

namespace {
// a frame error (dx, dy, dyaw) at pose `from` seen at pose `to`: its yaw
// error moves `to` by the lever arm from `from`
Matrix3d carry(const Matrix3d& cov, const Pose2& from, const Pose2& to) {
  Matrix3d J = Matrix3d::Identity();
  J(0, 2) = -(to.y - from.y);
  J(1, 2) = to.x - from.x;
  return J * cov * J.transpose();
}
}  // namespace

void FastSlam::update_covariance() {
  // called at the end of update(): updates_ already counts it
  const std::int64_t now = updates_ - 1;
  const Pose2 here = mean_pose();
  // the older frames the best particle saw a landmark of, each once
  seen_frames_.clear();
  for (const auto& sighting : best_sightings_) {
    const std::int64_t u = sighting.first / kIdsPerUpdate;
    if (sighting.first >= 0 && u < now && u < static_cast<std::int64_t>(anchors_.size())) seen_frames_.push_back(u);
  }
  std::sort(seen_frames_.begin(), seen_frames_.end());
  seen_frames_.erase(std::unique(seen_frames_.begin(), seen_frames_.end()), seen_frames_.end());
  // the anchor: the smallest of their frame errors here, else the last one
  Matrix3d anchor = carry(anchor_.common, anchor_.pose, here);
  std::int64_t from = -1;
  for (const std::int64_t u : seen_frames_) {
    const Anchor& a = anchors_[static_cast<std::size_t>(u)];
    const Matrix3d c = carry(a.common + a.relative, a.pose, here);
    if (from < 0 || c.trace() < anchor.trace()) {
      anchor = c;
      from = u;
    }
  }
  const Matrix3d cloud = cloud_covariance(here);  // here is mean_pose()
  cov_ = cloud + anchor;
  anchor_ = {here, anchor, Matrix3d::Zero()};
  anchors_.resize(static_cast<std::size_t>(updates_));
  anchors_[static_cast<std::size_t>(now)] = {here, anchor, cloud};
  // the other frames seen: their landmarks were seen again from here, at
  // `cloud` from the anchor's frame: the relative part takes it in as a
  // Kalman update (sightings from different poses: independent parts), the
  // common part never grows past the anchor's
  for (const std::int64_t u : seen_frames_) {
    if (u == from) continue;  // the anchor itself: its own error, nothing new
    Anchor& a = anchors_[static_cast<std::size_t>(u)];
    const Matrix3d common = carry(anchor, here, a.pose);
    if (common.trace() < a.common.trace()) a.common = common;
    const Matrix3d rel = carry(cloud, here, a.pose);
    const Matrix3d gain = a.relative * (a.relative + rel).completeOrthogonalDecomposition().pseudoInverse();
    const Matrix3d I_G = Matrix3d::Identity() - gain;
    const Matrix3d r = I_G * a.relative * I_G.transpose() + gain * rel * gain.transpose();
    a.relative = 0.5 * (r + r.transpose());
  }
}

}  // namespace paddock::slam
