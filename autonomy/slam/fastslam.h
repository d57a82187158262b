#pragma once
// FastSLAM 1.0 and 2.0 (Montemerlo et al., AAAI 2002 and IJCAI 2003; the
// paper's "State Estimation"): a particle filter over the base pose, each
// particle carrying its own map of cones as independent 2x2 EKFs.
//
// Motion (predict): the odometry's pose change d = (dx, dy, dyaw) in the
// previous base frame, with noise n ~ N(0, Q) added to it,
//   Q = diag(sxy^2, sxy^2, syaw^2),  sxy = motion_std_xy_per_m |d_xy|,
//   syaw = motion_std_yaw_per_m |d_xy| + motion_std_yaw_per_rad |dyaw|
// (a per-call model: predict is meant to get one frame's motion). Each
// particle keeps the predicted mean s^ = s (+) d and the covariance P of its
// pose since the last update, P' = F P F^T + G Q G^T, F = d(s (+) d)/ds,
// G = blockdiag(R(yaw), 1). The pose is sampled at the update: FastSLAM 1.0
// draws it from N(s^, P) (the motion model), FastSLAM 2.0 from the proposal
// that folds the frame's associated observations in.
//
// Measurement: an observation at (px, py) in the base frame is a range and
// bearing z = (|p|, atan2(py, px)) with R = diag(sr^2, sb^2), sr = range_std
// + range_std_per_m r, sb = bearing_std. For a landmark m seen from pose
// s = (x, y, yaw), with d = m - (x, y), q = |d|^2:
//   h(s, m) = (sqrt(q), atan2(d_y, d_x) - yaw)
//   H_m = dh/dm = [ d_x/sqrt(q)  d_y/sqrt(q) ]    H_s = dh/ds = [ -d_x/sqrt(q) -d_y/sqrt(q)  0 ]
//                 [ -d_y/q       d_x/q       ]                  [  d_y/q       -d_x/q       -1 ]
// Landmark EKF: S = H_m C H_m^T + R, K = C H_m^T S^-1, m += K nu, C = (I - K H_m) C
// (nu = z - h, bearing wrapped). A new landmark: m = s (+) p, C = H_m^-1 R H_m^-T.
//
// FastSLAM 2.0 proposal (Montemerlo 2003, eqs. for Sigma_s and mu_s), for the
// frame's associated observations in turn, starting from (mu, Sigma) = (s^, P):
//   Z = H_s Sigma H_s^T + H_m C H_m^T + R             (h, H at mu)
//   Sigma_s = (H_s^T (H_m C H_m^T + R)^-1 H_s + Sigma^-1)^-1 = Sigma - K_s Z K_s^T,  K_s = Sigma H_s^T Z^-1
//   mu_s = mu + Sigma_s H_s^T (H_m C H_m^T + R)^-1 nu = mu + K_s nu
// (the Kalman form of the same equations: it needs no inverse of Sigma, which
// is singular when the odometry is exact). The pose is then drawn from
// N(mu_s, Sigma_s) and the landmarks updated at it. The importance weight is
// the measurement likelihood under the pose-and-landmark linearisation,
//   w *= N(nu; 0, Z)  for each associated observation (Z and nu at the mu
//   before it: the sequential factorisation p(z_1..z_n) = prod p(z_k | z_<k)),
// and FastSLAM 1.0's w *= N(nu; 0, H_m C H_m^T + R) at the sampled pose. An
// observation that starts a landmark weighs new_landmark_likelihood (p0).
//
// Data association, per particle, by maximum likelihood: an observation's
// candidates are the landmarks within search_radius of where it lands (at
// s^), scored with N(nu; 0, Z) (FastSLAM 1.0: at the sampled pose, without the
// pose term) with association_std^2 I added to the landmark's covariance; one
// past the Mahalanobis gate (nu^T Z^-1 nu > association_gate) or below
// new_landmark_likelihood is no candidate. Mutual exclusion: the
// pairs are taken best first, each landmark and each observation once per
// frame. An observation left without a landmark starts a tentative one; it is
// confirmed after confirm_sightings sightings.
//
// Removal: a landmark is expected in a frame when it lies within view_range
// and view_half_fov of the particle's pose (or was seen), unless the frame's
// free-space boundary (update's free_range, from perception: the nearest
// obstacle that is no cone, per bearing) lies more than occlusion_margin
// nearer in its bearing: a cone behind a barrier is hidden, not missing. It
// is removed when,
// after remove_min_expected expectations, its sightings are below remove_ratio
// times them (ghosts), or after remove_misses expected frames in a row
// without a sighting (a cone that is gone: its long history of sightings
// would keep a ratio up for laps), a tentative one after
// remove_tentative_misses.
//
// Colour: each sighting votes for its colour, weight 1 (LiDAR intensity) or
// camera_vote_weight (camera); the colour is the most voted one.
//
// Resampling: low variance (Thrun et al., Probabilistic Robotics, table 4.4)
// when N_eff = 1 / sum w^2 < resample_neff_ratio N. pose() and map() are the
// highest-weight particle's (chosen before resampling, as the paper says).
//
// Map storage, copy on write: a particle's landmarks live in blocks of
// kLandmarkBlock held by std::shared_ptr; copying a particle (resampling)
// copies the block pointers only, and a write clones a block that another
// particle also holds (use_count() > 1). Blocks and not one pointer per
// landmark: landmarks are created in the order the car meets them, so the
// ones a frame touches (those in view) sit in a few neighbouring blocks, and
// a resample copies ~N/16 pointers instead of N (fewer reference-count
// updates, one allocation per touched block instead of one per landmark).
// Not a balanced tree (log N sharing, Montemerlo's): a map of a few hundred
// cones is a few dozen blocks; a resample of 200 particles with 150
// landmarks takes 9 us (bench/fastslam_bench.cc), the clones come later, on
// the writes of the next update (counted in its time).
// Removed landmarks stay as dead slots (indices never move).
//
// Bad input: a non-finite or too-near (< min_range) observation and a
// non-finite or absurd delta (over 1 km or 2 pi) are ignored and counted
// (rejected()), never a crash.
// Deterministic for a seed: its own std::mt19937_64, no global state.
// Threads (params.threads): the particles' update is split into contiguous
// runs, one a thread, each with its own scratch; the pose draws are made
// before, in the particles' order, so the result is bit for bit the same for
// any count. Copy on write: a block shared when a threaded update began is
// cloned by every particle that writes it (Particle::sharing_fixed); on one
// thread, by every writer while use_count() > 1. A copy of the filter shares
// the original's blocks, and has threads of its own.
#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <random>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "autonomy/common/cone.h"
#include "autonomy/common/geometry.h"
#include "autonomy/hal/messages.h"
#include "autonomy/common/params.h"
#include "autonomy/common/workers.h"
#include "autonomy/slam/cone_map.h"

namespace paddock::slam {

struct FastSlamParams {
  // 2: the proposal folds the measurements in, which pays where the motion
  // noise exceeds the measurement noise (the paper's reason to adopt it)
  int fastslam_version = 2;
  // 200: bench/fastslam_bench.cc, one update with ~20 observations on a map
  // of 150 landmarks on one core: 200 particles 1.7 ms mean, 2.1-2.9 ms
  // p99; 300: 2.5 ms, 3.0-3.8 ms p99. 200 keeps a 1.6x margin to a 5 ms
  // p99; more particles are more consistent (the noisy loop of
  // tests/slam/fastslam_test.cc: NEES within its 95 % bound on 64 % of
  // steps with 100, 73 % with 200, 81 % with 300)
  int particles = 200;
  // once the pose graph closed the loop and re-anchored the filter on the
  // optimised map (every particle is then the re-anchored one: the set has
  // no spread left to keep), it goes on with this many (0: particles); a
  // relocalisation re-anchors on the full set. Lap 1 maps from nothing and
  // needs the many; after it the particles localise in a mapped loop.
  // Measured with 100 against 200 (`paddock sweep`, 2026-11-28): six
  // shipped tracks x 3 seeds, mean ATE RMS, map RMSE and lap times the
  // same to 1-6 mm and 1 ms, 0 DOO and 0 OC either way; the noisy CI
  // scenario over 24 seeds, DOO on 7 seeds against 6 (a chaotic split,
  // seed by seed; 50: 7), mean ATE 0.219 against 0.217 m; the default run
  // 17 % faster. 50 against 100 (2026-11-29, once the pose graph held the
  // laps it had solved, LoopClosureParams::hold_optimised): seven shipped
  // trackdrives x 2 seeds and the noisy scenario x 24 seeds, mean ATE RMS
  // 0.100 / 0.254 m against 0.100 / 0.255 (clean / noisy), map RMSE 0.065
  // / 0.224 against 0.065 / 0.226, no cone hit in any of the 38 runs
  // either way; the default run 7 % faster on one core
  int closed_particles = 50;

  // measurement noise: a cone's centre from perception, 2 cm + 1 % of the
  // range and 0.2 deg (the object-level sensor is 2 cm + 0.2 %, 0.11 deg:
  // raw perception adds the centroid's bias from the cone's visible side)
  double range_std = 0.02;
  double range_std_per_m = 0.01;
  double bearing_std = 0.2 * kPi / 180.0;

  // odometry noise per predict (one frame's motion), as measured on the
  // velocity EKF's dead reckoning against the truth (FSG 2023, 1 m
  // segments): position 0.8 % of the distance along and 0.7 % across; yaw
  // 2.3e-4 rad rms per segment on straights (the gyro's noise and bias
  // residual: per time more than per metre, 3e-4 per m covers it down to
  // ~8 m/s) and 0.2 % of the angle turned (the model keeps 0.5 %, a MEMS
  // gyro's scale error)
  double motion_std_xy_per_m = 0.01;
  double motion_std_yaw_per_m = 3e-4;
  double motion_std_yaw_per_rad = 0.005;

  // data association
  // p0 (1/(m rad)): the density of a (range, bearing) innovation below which a
  // new landmark is the likelier explanation; at the default noise a match at
  // 10 m peaks near 400, so 1e-2 sits ~4.5 sigma out
  double new_landmark_likelihood = 1e-2;
  // chi-square, 2 dof: 16 (p = 3e-4): a cone 0.4 m from another is > 8 sigma away
  double association_gate = 16.0;
  // association only: this much std (each axis) is added to a landmark's
  // position when scoring it, for the drift a particle does not know about
  // (its pose relative to landmarks mapped a loop ago: the particle cloud's
  // spread shrinks with resampling, the true drift does not); it lets a loop
  // close after ~1 m of drift with cones >= 2 m apart
  double association_std = 0.3;
  // a cheap first gate: only landmarks this close to where the observation
  // lands are scored (well above the pose's drift over one frame)
  double search_radius = 2.0;
  // observations nearer than this have no stable bearing
  double min_range = 0.3;

  // a real cone is seen in most frames while the car approaches it; a ghost
  // of a good pipeline rarely repeats at one place (as ConeMapParams)
  int confirm_sightings = 5;

  // where a cone is expected to be seen: inside perception's reliable range
  // (the object sensor's 20 m) and field of view (180 deg), with a margin
  double view_range = 18.0;
  double view_half_fov = 80.0 * kPi / 180.0;
  // nor where the frame's free-space boundary (update's free_range) lies
  // nearer than the landmark by more than this: an obstacle hides it (a
  // cone close behind a barrier's face still counts as hidden)
  double occlusion_margin = 0.5;
  // removal: seen in fewer than remove_ratio of the frames it was expected
  // in (after remove_min_expected of them), or not seen in remove_misses
  // expected frames in a row
  double remove_ratio = 0.3;
  int remove_min_expected = 5;
  int remove_misses = 10;
  // a tentative landmark goes after this many expected frames in a row
  // without a sighting (a ghost passes out of view in a few frames)
  int remove_tentative_misses = 3;

  // resample when N_eff < ratio N (the usual half)
  double resample_neff_ratio = 0.5;
  // a camera colour vote outweighs a LiDAR intensity vote
  double camera_vote_weight = 3.0;

  // threads sharing the particles' update (contiguous runs of them, each
  // with its own scratch; the draws made before in the particles' order):
  // the result is the same for any count. 1: the caller's thread alone (a
  // sweep runs one run per core)
  int threads = 1;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(fastslam_version), {"", params::in(1, 2), "1: FastSLAM 1.0 (motion-model proposal), 2: FastSLAM 2.0 (proposal folds the measurements in)"});
    v(PADDOCK_PARAM(particles), {"", params::in(1, 100000), "number of particles"});
    v(PADDOCK_PARAM(closed_particles), {"", params::in(0, 100000), "particles after a loop closure re-anchored the filter on the optimised map (0: particles)"});
    v(PADDOCK_PARAM(range_std), {"m", params::above_up_to(0.0, 10.0), "range noise std of an observation (constant part)"});
    v(PADDOCK_PARAM(range_std_per_m), {"", params::in(0.0, 1.0), "range noise std per m of range"});
    v(PADDOCK_PARAM(bearing_std), {"rad", params::above_up_to(0.0, 1.0), "bearing noise std of an observation"});
    v(PADDOCK_PARAM(motion_std_xy_per_m), {"", params::in(0.0, 1.0), "odometry position noise std per m travelled (per predict)"});
    v(PADDOCK_PARAM(motion_std_yaw_per_m), {"rad/m", params::in(0.0, 1.0), "odometry yaw noise std per m travelled (per predict)"});
    v(PADDOCK_PARAM(motion_std_yaw_per_rad), {"", params::in(0.0, 1.0), "odometry yaw noise std per rad turned (per predict)"});
    v(PADDOCK_PARAM(new_landmark_likelihood), {"1/(m rad)", params::above(0.0), "innovation density below which an observation starts a new landmark (p0)"});
    v(PADDOCK_PARAM(association_gate), {"", params::above(0.0), "chi-square (2 dof) Mahalanobis gate of an association"});
    v(PADDOCK_PARAM(association_std), {"m", params::in(0.0, 10.0), "std added to a landmark's position when scoring an association (unmodelled drift)"});
    v(PADDOCK_PARAM(search_radius), {"m", params::above_up_to(0.0, 100.0), "only landmarks this close to an observation are scored"});
    v(PADDOCK_PARAM(min_range), {"m", params::above_up_to(0.0, 10.0), "nearer observations are rejected"});
    v(PADDOCK_PARAM(confirm_sightings), {"", params::in(1, 100000), "sightings before a landmark is confirmed"});
    v(PADDOCK_PARAM(view_range), {"m", params::above_up_to(0.0, 1000.0), "a landmark nearer than this (and in view_half_fov) is expected to be seen"});
    v(PADDOCK_PARAM(view_half_fov), {"rad", params::above_up_to(0.0, kPi), "half the field of view in which a landmark is expected to be seen"});
    v(PADDOCK_PARAM(occlusion_margin), {"m", params::at_least(0.0), "a landmark this far beyond the frame's free-space boundary is hidden, not expected"});
    v(PADDOCK_PARAM(remove_ratio), {"", params::fraction(), "removed when seen in fewer than this share of the frames it was expected in"});
    v(PADDOCK_PARAM(remove_min_expected), {"", params::in(1, 100000), "expected frames before remove_ratio applies"});
    v(PADDOCK_PARAM(remove_misses), {"", params::in(1, 100000), "removed after this many expected frames in a row without a sighting"});
    v(PADDOCK_PARAM(remove_tentative_misses), {"", params::in(1, 100000), "a tentative landmark is removed after this many expected frames in a row without a sighting"});
    v(PADDOCK_PARAM(resample_neff_ratio), {"", params::fraction(), "resample when N_eff < ratio * particles"});
    v(PADDOCK_PARAM(camera_vote_weight), {"", params::above_up_to(0.0, 1000.0), "weight of a camera colour vote (a LiDAR vote weighs 1)"});
    v(PADDOCK_PARAM(threads), {"", params::in(1, Workers::kMaxThreads), "threads sharing the particles' update (the result is the same for any count)"});
  }
};

// one cone of one frame
struct Observation {
  Vec2 position;  // base frame, m
  ConeColor color = ConeColor::Unknown;
  bool colour_from_camera = false;
};

struct Landmark {
  // who started it: (the update's number) * kIdsPerUpdate + (the observation's
  // index in it). Every particle that starts a landmark from the same
  // observation gives it the same id (all of them do in the first frame), so
  // ids name the same cone across particles and lineages
  std::int64_t id = -1;
  Vec2 mean;                               // map frame, m
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();  // m^2
  int sightings = 0;                       // frames it was associated in
  int expected = 0;                        // frames it was in view (or seen)
  std::array<double, 5> votes{};           // per ConeColor, in enum order
  bool confirmed = false;
  ConeColor color() const;                 // the most voted colour; unknown when no coloured vote
};

class FastSlam {
 public:
  static constexpr int kLandmarkBlock = 16;
  static constexpr std::int64_t kIdsPerUpdate = 1 << 16;  // observations of one update past this are rejected

  // throws std::invalid_argument on invalid params
  FastSlam(const FastSlamParams& p, std::uint64_t seed);

  // every particle at pose, with an empty map
  void reset(const Pose2& pose);
  // the motion since the last call, as the odometry measured it: the base's
  // pose change in the previous base frame
  void predict(const Pose2& delta);
  // one frame of cone observations (base frame, at the pose after the last
  // predict) and, if the sensor gives one, its free-space boundary
  // (hal::ConeDetections::free_range: per bearing bin the range of the
  // nearest obstacle that hides cones; empty: none given)
  void update(const std::vector<Observation>& obs, const std::vector<float>& free_range = {});

  // the highest-weight particle's pose
  Pose2 pose() const;
  // its confirmed landmarks
  std::vector<Landmark> map() const;
  // all its landmarks, tentative ones too
  std::vector<Landmark> all_landmarks() const;
  // the particle set's weighted mean (x, y, yaw; yaw averaged about the
  // best particle's)
  Pose2 mean_pose() const;
  // the estimate's covariance (x, y, yaw) in the world frame after the last
  // update: the particle set's covariance plus its map's anchor (below)
  const Eigen::Matrix3d& pose_covariance() const { return cov_; }
  // the particle set's own weighted covariance about mean_pose()
  Eigen::Matrix3d cloud_covariance() const;

  std::size_t particle_count() const { return particles_.size(); }
  double effective_particles() const { return neff_; }  // N_eff after the last update
  int resamples() const { return resamples_; }
  std::int64_t updates() const { return updates_; }  // update() calls so far (the next one's number)
  int rejected() const { return rejected_; }  // ignored observations and deltas
  // low-variance resampling now (update() does it when N_eff is low)
  void resample();

  // the highest-weight particle's association of the last update: for each
  // observation it used (finite, beyond min_range), the id of the landmark
  // it was associated with or started, and the observation (base frame)
  const std::vector<std::pair<std::int64_t, Vec2>>& best_sightings() const { return best_sightings_; }
  // after a back end (the pose graph) re-estimated the highest-weight
  // particle's pose and some of its landmarks (by id): every particle becomes
  // that particle, at `pose`, with those landmarks moved, equal weights; the
  // landmarks started by update `forget_from` or later are dropped (a
  // relocalisation's: the lost frames' ghosts). The set is then `particles`
  // strong (0 or less: FastSlamParams::particles; reset() goes back to that)
  void reanchor(const Pose2& pose, const std::vector<std::pair<std::int64_t, Vec2>>& landmarks,
                std::int64_t forget_from = std::numeric_limits<std::int64_t>::max(), int particles = 0);

 private:
  struct Slot {
    Landmark lm;
    int misses = 0;  // expected frames in a row without a sighting
  };
  struct Block {
    std::array<Slot, kLandmarkBlock> slots;
  };
  // a box holding every landmark mean a block has held (it only grows: a
  // mean moves by centimetres, a dead slot stays in it); a block whose box
  // is out of a frame's reach is skipped without reading it
  struct Bounds {
    double lo_x = std::numeric_limits<double>::infinity(), lo_y = std::numeric_limits<double>::infinity();
    double hi_x = -std::numeric_limits<double>::infinity(), hi_y = -std::numeric_limits<double>::infinity();
    void cover(Vec2 m);
    // a lower bound of squared_norm(m - c) for every m in the box, in
    // floating point too (each difference rounds monotonically)
    double squared_distance(Vec2 c) const;
  };
  // a block with an alive slot, as a particle holds it: the pointer (shared
  // between particles until written), its number, which of its slots are
  // alive (bit j: slot j) and the bounds of their means. A particle's live
  // blocks are a short list: most slots die young (a ghost, a far cone seen
  // once), a particle gathers thousands of them over ten laps, and neither
  // the search of nearby landmarks nor a resample's copy touches their
  // blocks. A block whose slots have all died is let go.
  struct LiveBlock {
    std::shared_ptr<Block> block;
    int number;
    std::uint32_t alive;
    Bounds bounds;
    // held by another particle when a threaded update began (see
    // Particle::sharing_fixed)
    bool shared = false;
  };
  static_assert(kLandmarkBlock <= 32, "LiveBlock::alive holds a block's slots");
  // a block by number, for reading: its live entry's block and position
  // (null, -1 once its slots all died); plain data, copied as a whole
  struct BlockRef {
    Block* block;
    int live;
  };
  struct Particle {
    Pose2 pose;                                 // s^ until the update samples it
    Eigen::Matrix3d P = Eigen::Matrix3d::Zero();  // pose covariance since the last update
    double weight = 1.0;
    // the parent's index while an unchanged copy from a resample (its
    // copies are consecutive), -1 once updated
    int copy_of = -1;
    // during an update split between threads: whether a block is shared
    // (written as a clone) is what it was when the update began
    // (LiveBlock::shared), not its use count now. Another thread's particle
    // may let go of a block meanwhile, and its reads of it must not meet a
    // write in place here; a block shared then is never written in place
    // during the update, one not shared then is this particle's alone. Alone
    // on one thread the count decides (the last holder writes in place)
    bool sharing_fixed = false;
    std::vector<LiveBlock> live;                 // by number
    std::vector<BlockRef> blocks;                // by number
    int size = 0;                                // slots used
    const Slot& slot(int i) const { return blocks[i / kLandmarkBlock].block->slots[i % kLandmarkBlock]; }
    Slot& mutable_slot(int i);                   // clones a shared block first
    void clone(BlockRef& ref, LiveBlock& lb);    // (mutable_slot's copy on write)
    int add(const Slot& s);                      // a new alive slot
    void sweep();                                // lets go of the live blocks with no alive slot left
  };
  // an update's valid observations: range and bearing, noise, the
  // observation; and their order along the base frame's x axis, the same
  // for every particle (the association's search)
  struct Frame {
    std::vector<Eigen::Vector2d> z;
    std::vector<Eigen::Matrix2d> R;
    std::vector<const Observation*> obs;
    std::vector<double> sorted_x;  // the observations' position.x, ascending
    std::vector<double> sorted_y;  // their position.y
    std::vector<int> by_x;         // their indices in that order
  };
  // an association candidate: its log-likelihood (once scored) and its
  // parts, observation, position in near_
  struct Candidate {
    double ll;
    double d2, det;
    int obs;
    int near;
    bool scored;
  };

  void prepare(const std::vector<Observation>& obs);  // into frame_
  // the proposal of FastSLAM 2.0 before its draw: mean, covariance and the
  // observations' log-likelihood
  struct Proposal {
    Pose2 mean;
    Eigen::Matrix3d cov;
    double log_lik;
  };

  // one thread's scratch of update_particle (kept to spare the
  // allocations): the landmarks near the particle (indices ascending, their
  // blocks' positions in Particle::live, their means), where the
  // observations land, the association's candidates and result
  // (observation -> position in near or -1; near_taken: the near landmarks
  // taken), the 2.0 proposal
  struct Scratch {
    std::vector<int> in_reach;  // live blocks (positions) within reach
    std::vector<int> near;
    std::vector<int> near_live;
    std::vector<double> near_x, near_y;
    std::vector<double> land_x, land_y;
    std::vector<Candidate> cands, rivals;
    std::vector<int> cands_per_obs, cands_per_near;
    std::vector<int> match;
    std::vector<char> near_taken;
    Proposal proposal;
  };

  void update_particle(Particle& p, const Frame& f, bool copy_of_previous, double& log_lik,
                       std::vector<std::int64_t>& ids, const Eigen::Vector3d& draw, Scratch& w);
  // its parts, in order: the landmarks near the particle (into w.near), the
  // association (into w.match and w.near_taken), the 2.0 proposal (the pose
  // is drawn from it in update_particle), the associated landmarks' EKFs,
  // the expectations and removals, the new tentative landmarks
  void gather_near(const Particle& p, Scratch& w);
  const std::vector<int>& associate(const Particle& p, const Frame& f, Scratch& w);
  void find_candidates(const Particle& p, const Frame& f, Scratch& w);  // into w.cands
  void propose(const Particle& p, const Frame& f, const std::vector<int>& match, Scratch& w);  // into w.proposal
  void update_landmarks(Particle& p, const Frame& f, const std::vector<int>& match, double& log_lik, Scratch& w);
  // (cy, sy: cos and sin of the sampled pose's yaw)
  void expect_and_remove(Particle& p, double cy, double sy, Scratch& w);
  void add_new_landmarks(Particle& p, const Frame& f, const std::vector<int>& match, double cy, double sy,
                         double& log_lik, std::vector<std::int64_t>& ids);
  // three standard normal draws of rng_ (a particle's, for its pose)
  Eigen::Vector3d standard_normals();
  // mean + L n, L L^T = cov (by the eigenvectors where cov is only semi-definite)
  Pose2 sample_pose(const Pose2& mean, const Eigen::Matrix3d& cov, const Eigen::Vector3d& n);
  std::vector<Landmark> landmarks(bool confirmed_only) const;

  FastSlamParams params_;
  std::mt19937_64 rng_;
  std::vector<Particle> particles_;
  int best_ = 0;
  double neff_ = 0.0;
  int resamples_ = 0;
  int rejected_ = 0;
  std::int64_t updates_ = 0;
  std::vector<std::vector<std::int64_t>> frame_ids_;  // per particle, per observation, this update
  std::vector<std::pair<std::int64_t, Vec2>> best_sightings_;
  // The map's own error in the world frame. Resampling soon leaves the
  // particles one ancestor, so they share one map and their spread is the
  // pose's uncertainty relative to that map only, not to the world (Bailey,
  // Nieto, Nebot 2006, "Consistency of the FastSLAM algorithm"): alone, it
  // makes the estimate overconfident over a lap. So each update's new
  // landmarks inherit a frame error (by the update number in their ids): the
  // estimate's anchor then (common: shared by all it was carried to) plus
  // the set's spread then (relative: theirs alone). The estimate's
  // covariance is the set's spread plus its anchor: the smallest frame error
  // among the older landmarks the best particle saw, carried to the current
  // pose (a frame's yaw error moves a point by its lever arm); without one,
  // the last anchor. A frame seen again from a pose anchored elsewhere takes
  // the new sighting into its relative part as a Kalman update and keeps the
  // smaller common part. The first landmarks, made at the start pose, have
  // none: seeing them again (the loop's end) brings the covariance back to
  // the set's spread. Reported only: no estimate depends on it.
  struct Anchor {
    Pose2 pose;  // where the frame's error is taken
    Eigen::Matrix3d common = Eigen::Matrix3d::Zero();
    Eigen::Matrix3d relative = Eigen::Matrix3d::Zero();
  };
  std::vector<Anchor> anchors_;  // by update number
  Anchor anchor_;                // the estimate's, at the last update (relative 0)
  Eigen::Matrix3d cov_ = Eigen::Matrix3d::Zero();
  std::vector<std::int64_t> seen_frames_;  // scratch of update_covariance
  void update_covariance();
  Eigen::Matrix3d cloud_covariance(const Pose2& mean) const;  // about mean_pose(), computed once by the caller
  // scratch of resample: the parent of each new particle, the new set
  std::vector<int> picks_;
  std::vector<Particle> spare_;
  // scratch of update and update_particle (kept to spare the allocations)
  Frame frame_;
  const std::vector<float>* free_range_ = nullptr;  // update()'s free-space boundary, null if it hides nothing
  std::vector<double> log_lik_;
  std::vector<Eigen::Vector3d> draws_;  // per particle, this update's
  // the particle update's threads (FastSlamParams::threads) and one scratch each
  Workers workers_;
  std::vector<Scratch> scratch_;
};

}  // namespace paddock::slam
