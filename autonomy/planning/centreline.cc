#include "autonomy/planning/centreline.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

namespace paddock::planning {

namespace {

// 2 exp(-(x/sigma)^2 / 2) - 1: 1 at x = 0, -1 far away
double bell(double x, double sigma) {
  const double r = x / sigma;
  return 2.0 * std::exp(-0.5 * r * r) - 1.0;
}

// what the search needs of an edge, computed once
struct EdgeInfo {
  Vec2 mid;
  Vec2 a;              // position of cone a
  Vec2 dir;            // unit vector from cone a to cone b
  double length = 0.0;  // distance between the cones (m)
  // the colours around the edge as evidence that cone a's side is the blue
  // (left) one: +1 for it, -1 against, an average over the coloured cones
  // near the midpoint (the edge's own two count double); 0 when none
  double colour_a_left = 0.0;
};

// a state of the search: where it stands and how it got there
struct Node {
  Vec2 p;                      // current point (m)
  Vec2 dir{1.0, 0.0};          // unit direction of the last step
  double turn = 0.0;           // predicted heading change of the next step (rad)
  double last_turn = 0.0;      // heading change of the last step (rad)
  Vec2 pred_dir{1.0, 0.0};     // dir turned by `turn`: where the next step should head
  std::size_t edge = kNoCone;  // the edge of the current point, none at the vehicle
};

// one scored candidate
struct Candidate {
  std::size_t edge = 0;
  double reward = 0.0;
  RewardTerms terms;
  Node next;
  bool closes = false;  // steps back onto one of the first points: the lap closes
  int target = -1;      // which of the first points, when it closes
};

// the few edges of the branch being looked ahead (depth <= kMaxDepth)
constexpr int kMaxDepth = CentrelineParams::kMaxDepth;
constexpr int kMaxBeam = CentrelineParams::kMaxBeam;
struct Branch {
  std::array<std::size_t, kMaxDepth> edges{};
  int size = 0;
  bool contains(std::size_t e) const {
    for (int i = 0; i < size; ++i)
      if (edges[static_cast<std::size_t>(i)] == e) return true;
    return false;
  }
};

class Search {
 public:
  Search(const Triangulation& tri, const std::vector<Cone>& cones, const CentrelineParams& p)
      : p_(p) {
    const double wsum = p.weight_colour + p.weight_width + p.weight_angle + p.weight_step +
                        p.weight_prediction + p.weight_crossing;
    inv_weight_sum_ = 1.0 / wsum;
    cos_max_turn_ = std::cos(p.max_turn);
    cos_closure_ = std::cos(p.closure_max_angle);
    // what each edge brings by itself
    info_.resize(tri.edges.size());
    for (std::size_t i = 0; i < tri.edges.size(); ++i) {
      const TriEdge& e = tri.edges[i];
      EdgeInfo& in = info_[i];
      in.mid = e.midpoint;
      in.a = cones[e.a].position;
      const Vec2 ab = cones[e.b].position - in.a;
      in.dir = e.length > 0.0 ? ab / e.length : Vec2{1.0, 0.0};
      in.length = e.length;
      edge_a_.push_back(e.a);
      edge_b_.push_back(e.b);
    }
    build_neighbours();
    build_cone_lists(cones, tri);
    used_.assign(info_.size(), 0);
    buffers_.resize(static_cast<std::size_t>(p.horizon_depth) + 1);
  }

  CentrelineResult run(const Pose2& start) {
    CentrelineResult out;
    Node cur;
    cur.p = start.position();
    cur.dir = start.heading();
    cur.turn = 0.0;
    cur.pred_dir = cur.dir;
    double length = 0.0;  // along the committed points (m)
    std::vector<Vec2> arrival;  // the direction of the step onto each point

    while (true) {
      if (static_cast<int>(out.points.size()) >= p_.max_points) {
        out.stop = CentrelineStop::MaxPoints;
        break;
      }
      if (length >= p_.max_length) {
        out.stop = CentrelineStop::MaxLength;
        break;
      }
      // every candidate above the threshold, each valued over the horizon
      closure_ok_ = out.points.size() > static_cast<std::size_t>(p_.closure_points);
      path_length_ = length;
      first_points_ = &out.steps;
      arrival_ = &arrival;
      std::vector<Candidate>& cands = buffers_[0];
      Branch branch;
      collect(cur, branch, p_.first_beam_width, cands);
      if (cands.empty()) {
        out.stop = CentrelineStop::NoCandidate;
        break;
      }
      std::size_t best = 0;
      double best_value = -1.0;
      for (std::size_t k = 0; k < cands.size(); ++k) {
        const Candidate& c = cands[k];
        double v = c.reward;
        if (c.closes) {
          v += c.reward * (p_.horizon_depth - 1);
        } else {
          branch.edges[0] = c.edge;
          branch.size = 1;
          v += lookahead(with_prediction(c.next), p_.horizon_depth - 1, branch);
        }
        // cands is sorted best reward first, so ties keep the better step
        if (v > best_value + 1e-12) {
          best_value = v;
          best = k;
        }
      }
      // every continuation poor: better to stop here (the end of the seen
      // track, or a gap the search cannot bridge) than to wander off it
      if (best_value < p_.min_horizon_reward * p_.horizon_depth) {
        out.stop = CentrelineStop::PoorContinuation;
        break;
      }
      const Candidate chosen = cands[best];
      const int ncands = static_cast<int>(cands.size());
      if (chosen.closes) {
        // the lap: from the point it steps back onto to the current one
        const std::size_t j = static_cast<std::size_t>(chosen.target);
        out.points.erase(out.points.begin(), out.points.begin() + static_cast<std::ptrdiff_t>(j));
        out.steps.erase(out.steps.begin(), out.steps.begin() + static_cast<std::ptrdiff_t>(j));
        out.closed = true;
        out.stop = CentrelineStop::LoopClosed;
        break;
      }
      CentrelineStep st;
      st.edge = chosen.edge;
      st.point = chosen.next.p;
      st.terms = chosen.terms;
      st.reward = chosen.reward;
      st.horizon_reward = best_value;
      st.candidates = ncands;
      if (!out.points.empty()) length += distance(out.points.back(), st.point);
      out.points.push_back(st.point);
      out.steps.push_back(st);
      arrival.push_back(chosen.next.dir);
      used_[chosen.edge] = 1;
      cur = with_prediction(chosen.next);
    }

    // the length along the points, with the closing step of a lap
    out.length = 0.0;
    for (std::size_t i = 1; i < out.points.size(); ++i)
      out.length += distance(out.points[i - 1], out.points[i]);
    if (out.closed && out.points.size() > 1)
      out.length += distance(out.points.back(), out.points.front());
    if (out.points.size() < 2 || (out.closed && out.points.size() < 3)) {
      out.status = CentrelineStatus::NoPath;
      out.reason = "centreline: the search found " + std::to_string(out.points.size()) +
                   " point(s) ahead of the vehicle (" + to_string(out.stop) + ")";
      out.closed = false;
      return out;
    }
    out.status = CentrelineStatus::Ok;
    return out;
  }

 private:
  // the edges whose midpoints lie within the search radius of each edge's
  // midpoint (CSR lists), by sorting the midpoints into square cells
  void build_neighbours() {
    const std::size_t n = info_.size();
    const double cell = p_.search_radius;
    const double r2 = p_.search_radius * p_.search_radius;
    // cell coordinates, clamped so that far-away cones cannot overflow
    auto cell_of = [&](double v) {
      const double c = std::floor(v / cell);
      return static_cast<std::int64_t>(std::clamp(c, -1e15, 1e15));
    };
    std::vector<std::pair<std::pair<std::int64_t, std::int64_t>, std::size_t>> keyed(n);
    for (std::size_t i = 0; i < n; ++i)
      keyed[i] = {{cell_of(info_[i].mid.x), cell_of(info_[i].mid.y)}, i};
    std::sort(keyed.begin(), keyed.end());
    nb_begin_.assign(n + 1, 0);
    nb_.clear();
    for (std::size_t i = 0; i < n; ++i) {
      const auto key = std::make_pair(cell_of(info_[i].mid.x), cell_of(info_[i].mid.y));
      for (std::int64_t dx = -1; dx <= 1; ++dx) {
        const auto lo = std::make_pair(std::make_pair(key.first + dx, key.second - 1), std::size_t{0});
        const auto hi = std::make_pair(std::make_pair(key.first + dx, key.second + 1), n);
        auto it = std::lower_bound(keyed.begin(), keyed.end(), lo);
        const auto end = std::upper_bound(it, keyed.end(), hi);
        for (; it != end; ++it) {
          const std::size_t j = it->second;
          if (j != i && squared_norm(info_[j].mid - info_[i].mid) <= r2) nb_.push_back(j);
        }
      }
      nb_begin_[i + 1] = nb_.size();
    }
  }

  // one pass over the cones near each edge's midpoint:
  //  - the cones within search_radius / 2 + min_clearance (a CSR list): a
  //    cone closer than min_clearance to a step between two midpoints at
  //    most search_radius apart is in the list of one of them;
  //  - the colour evidence (EdgeInfo::colour_a_left): a blue cone on cone
  //    a's side of the midpoint, or a yellow one on b's side, says a's side
  //    is the left one. A neighbour's side is that of its projection onto
  //    the edge (cones near the perpendicular bisector say nothing); the
  //    edge's own cones count double, and one colour on both of them (a
  //    boundary, or the strip between two lanes) counts against either way.
  //    Averaged over several cones, one swapped colour does not turn a
  //    boundary into a rung.
  void build_cone_lists(const std::vector<Cone>& cones, const Triangulation& tri) {
    for (std::size_t i = 0; i < cones.size(); ++i)
      if (i < tri.representative.size() && tri.representative[i] == i) {
        cone_pos_.push_back(cones[i].position);
        cone_index_.push_back(i);
      }
    const std::size_t n = info_.size();
    const double reach_list = 0.5 * p_.search_radius + p_.min_clearance;
    const double reach = std::max(reach_list, p_.colour_radius);
    const double list2 = reach_list * reach_list, colour2 = p_.colour_radius * p_.colour_radius;
    const double cell = std::max(reach, 1.0);
    auto cell_of = [&](double v) {
      return static_cast<std::int64_t>(std::clamp(std::floor(v / cell), -1e15, 1e15));
    };
    auto coloured = [](ConeColor c) { return c == ConeColor::Blue || c == ConeColor::Yellow; };
    auto vote = [](ConeColor c, bool a_side) { return (c == ConeColor::Blue) == a_side ? 1.0 : -1.0; };
    std::vector<std::pair<std::pair<std::int64_t, std::int64_t>, std::size_t>> keyed(cone_pos_.size());
    for (std::size_t i = 0; i < cone_pos_.size(); ++i)
      keyed[i] = {{cell_of(cone_pos_[i].x), cell_of(cone_pos_[i].y)}, i};
    std::sort(keyed.begin(), keyed.end());
    cone_begin_.assign(n + 1, 0);
    cone_list_.clear();
    for (std::size_t e = 0; e < n; ++e) {
      EdgeInfo& in = info_[e];
      const Vec2 m = in.mid;
      const std::size_t ia = edge_a_[e], ib = edge_b_[e];
      double sum = 0.0, weight = 0.0;
      const bool same = coloured(cones[ia].color) && cones[ia].color == cones[ib].color;
      for (std::size_t i : {ia, ib}) {
        if (!coloured(cones[i].color)) continue;
        sum += 2.0 * (same ? -1.0 : vote(cones[i].color, i == ia));
        weight += 2.0;
      }
      const std::int64_t cx = cell_of(m.x), cy = cell_of(m.y);
      for (std::int64_t dx = -1; dx <= 1; ++dx) {
        const auto lo = std::make_pair(std::make_pair(cx + dx, cy - 1), std::size_t{0});
        const auto hi = std::make_pair(std::make_pair(cx + dx, cy + 1), cone_pos_.size());
        auto it = std::lower_bound(keyed.begin(), keyed.end(), lo);
        const auto end = std::upper_bound(it, keyed.end(), hi);
        for (; it != end; ++it) {
          const Vec2 d = cone_pos_[it->second] - m;
          const double d2 = squared_norm(d);
          if (d2 <= list2) cone_list_.push_back(it->second);
          const std::size_t q = cone_index_[it->second];
          if (d2 > colour2 || q == ia || q == ib || !coloured(cones[q].color)) continue;
          const double t = dot(d, -in.dir);  // > 0 on a's side (dir points from a to b)
          if (t * t < 0.0625 * d2) continue;
          sum += vote(cones[q].color, t > 0.0);
          weight += 1.0;
        }
      }
      in.colour_a_left = weight > 0.0 ? sum / weight : 0.0;
      cone_begin_[e + 1] = cone_list_.size();
    }
  }

  // true when the step from s (a midpoint) onto edge c's midpoint keeps
  // min_clearance from every cone: it does not cut through a boundary
  bool clear(const Node& s, std::size_t c) const {
    if (s.edge == kNoCone) return clear_all(s, c);
    const double c2 = p_.min_clearance * p_.min_clearance;
    auto near = [&](std::size_t i) {
      const Vec2 q = cone_pos_[i];
      return squared_norm(q - closest_on_segment(s.p, info_[c].mid, q)) < c2;
    };
    for (std::size_t k = cone_begin_[s.edge]; k < cone_begin_[s.edge + 1]; ++k)
      if (near(cone_list_[k])) return false;
    for (std::size_t k = cone_begin_[c]; k < cone_begin_[c + 1]; ++k)
      if (near(cone_list_[k])) return false;
    return true;
  }

  // the same against every cone, for the first step (from the vehicle)
  bool clear_all(const Node& s, std::size_t c) const {
    const double c2 = p_.min_clearance * p_.min_clearance;
    for (const Vec2& q : cone_pos_)
      if (squared_norm(q - closest_on_segment(s.p, info_[c].mid, q)) < c2) return false;
    return true;
  }

  static Vec2 closest_on_segment(Vec2 a, Vec2 b, Vec2 q) {
    const Vec2 ab = b - a;
    const double l2 = squared_norm(ab);
    const double t = l2 > 0.0 ? std::clamp(dot(q - a, ab) / l2, 0.0, 1.0) : 0.0;
    return a + ab * t;
  }

  // a node about to be expanded: its predicted heading (once per node, not
  // per candidate scored)
  static Node with_prediction(Node n) {
    n.pred_dir = rotate(n.dir, n.turn);
    return n;
  }

  // the reward of stepping from s onto edge c's midpoint; false when the
  // midpoint is not a candidate (too near, too far, outside the forward cone)
  bool score(const Node& s, std::size_t c, Candidate& out) const {
    const EdgeInfo& e = info_[c];
    const Vec2 d = e.mid - s.p;
    const double l2 = squared_norm(d);
    if (l2 < p_.min_step * p_.min_step || l2 > p_.search_radius * p_.search_radius) return false;
    const double l = std::sqrt(l2);
    const double along = dot(s.dir, d);
    if (along < cos_max_turn_ * l) return false;
    const double across = cross(s.dir, d);
    const Vec2 u = d / l;
    RewardTerms t;
    // colour: blue on the left and yellow on the right of the step
    t.colour = cross(u, e.a - e.mid) > 0.0 ? e.colour_a_left : -e.colour_a_left;
    // the track width: the edge's extent across the direction of travel (a
    // diagonal rung between staggered cones is longer than the track is wide)
    t.width = track_width_reward(e.length * std::abs(cross(u, e.dir)), p_);
    const double turn = std::atan2(across, along);
    t.angle = bell(turn, p_.angle_sigma);
    t.step = bell(l - p_.step_preferred, p_.step_sigma);
    // the prediction: the heading turned as much again as over the last two
    // steps on average (the midpoints zig-zag), at this candidate's distance
    const Vec2 predicted = s.p + s.pred_dir * l;
    t.prediction = bell(std::sqrt(squared_norm(e.mid - predicted)), p_.prediction_sigma);
    // a track crossing (rung) is crossed squarely, a boundary edge lengthwise
    t.crossing = 2.0 * std::abs(cross(u, e.dir)) - 1.0;
    out.edge = c;
    out.terms = t;
    out.reward = (p_.weight_colour * t.colour + p_.weight_width * t.width +
                  p_.weight_angle * t.angle + p_.weight_step * t.step +
                  p_.weight_prediction * t.prediction + p_.weight_crossing * t.crossing) *
                 inv_weight_sum_;
    out.next.p = e.mid;
    out.next.dir = u;
    out.next.turn = 0.5 * (turn + s.last_turn);
    out.next.last_turn = turn;
    out.next.edge = c;
    out.closes = false;
    out.target = -1;
    return true;
  }

  // the best `keep` candidates from s above min_reward that keep clear of
  // the cones, best first
  void collect(const Node& s, const Branch& branch, int keep, std::vector<Candidate>& out) const {
    out.clear();
    Candidate c;
    auto consider = [&](std::size_t j) {
      if (candidate(s, j, branch, c)) out.push_back(c);
    };
    if (s.edge == kNoCone) {
      for (std::size_t j = 0; j < info_.size(); ++j) consider(j);
    } else {
      for (std::size_t k = nb_begin_[s.edge]; k < nb_begin_[s.edge + 1]; ++k) consider(nb_[k]);
    }
    // best first; ties by edge index so the order never depends on the sort
    std::sort(out.begin(), out.end(), [](const Candidate& x, const Candidate& y) {
      return x.reward > y.reward || (x.reward == y.reward && x.edge < y.edge);
    });
    // the clearance test last (it is the costly one), best first, until the beam is full
    std::size_t n = 0;
    for (std::size_t k = 0; k < out.size() && n < static_cast<std::size_t>(keep); ++k) {
      if (clear(s, out[k].edge)) out[n++] = out[k];
    }
    out.resize(n);
  }

  // scores edge j as the next step from s into c: false when it is no
  // candidate (reused, too near or far, outside the forward cone, below
  // min_reward); the clearance is not tested here
  bool candidate(const Node& s, std::size_t j, const Branch& branch, Candidate& c) const {
    if (j == s.edge || branch.contains(j)) return false;
    int target = -1;
    if (used_[j]) {
      // a used edge is taken again only to close the lap
      if (!closure_ok_ || path_length_ < p_.closure_min_length) return false;
      for (int k = 0; k < p_.closure_points; ++k)
        if ((*first_points_)[static_cast<std::size_t>(k)].edge == j) target = k;
      if (target < 0) return false;
    }
    if (!score(s, j, c) || !(c.reward >= p_.min_reward)) return false;
    if (target >= 0) {
      // ... heading the way the path first went through that point
      const Vec2 first = (*arrival_)[static_cast<std::size_t>(target)];
      if (dot(first, c.next.dir) < cos_closure_) return false;
      c.closes = true;
      c.target = target;
    }
    return true;
  }

  // the best reward of one more step from s (the last level of the
  // look-ahead: no list, no sort; clearance only for a better candidate)
  double best_step(const Node& s, const Branch& branch) const {
    double best = 0.0;
    Candidate c;
    for (std::size_t k = nb_begin_[s.edge]; k < nb_begin_[s.edge + 1]; ++k) {
      const std::size_t j = nb_[k];
      if (!candidate(s, j, branch, c) || c.reward <= best) continue;
      if (clear(s, j)) best = c.reward;
    }
    return best;
  }

  // the best cumulative reward of up to `depth` more steps from s; a dead
  // end scores 0 for each step it misses, and a closing step counts as if
  // the lap went on equally well
  double lookahead(const Node& s, int depth, Branch& branch) {
    if (depth <= 0) return 0.0;
    if (depth == 1) return best_step(s, branch);
    std::vector<Candidate>& cands = buffers_[static_cast<std::size_t>(branch.size)];
    collect(s, branch, p_.beam_width, cands);
    double best = 0.0;
    for (std::size_t k = 0; k < cands.size(); ++k) {
      const Candidate c = cands[k];  // a copy: deeper levels reuse other buffers only
      double v = c.reward;
      if (c.closes) {
        v += c.reward * (depth - 1);
      } else {
        branch.edges[static_cast<std::size_t>(branch.size++)] = c.edge;
        v += lookahead(with_prediction(c.next), depth - 1, branch);
        --branch.size;
      }
      best = std::max(best, v);
    }
    return best;
  }

  const CentrelineParams& p_;
  std::vector<EdgeInfo> info_;
  std::vector<std::size_t> nb_begin_, nb_;
  std::vector<char> used_;
  std::vector<Vec2> cone_pos_;                  // the triangulated cones
  std::vector<std::size_t> cone_index_;         // their indices in the input
  std::vector<std::size_t> edge_a_, edge_b_;    // each edge's cones (input indices)
  std::vector<std::size_t> cone_begin_, cone_list_;  // CSR: cones near each edge
  std::vector<std::vector<Candidate>> buffers_;  // one per look-ahead level
  double inv_weight_sum_ = 1.0;
  double cos_max_turn_ = 0.0;
  double cos_closure_ = 0.0;
  // the committed path, as the candidates of one step see it
  bool closure_ok_ = false;
  double path_length_ = 0.0;
  const std::vector<CentrelineStep>* first_points_ = nullptr;
  const std::vector<Vec2>* arrival_ = nullptr;
};

}  // namespace

double track_width_reward(double w, const CentrelineParams& p) {
  if (w < p.width_min) {
    const double r = (w - p.width_min) / p.width_sigma;
    return 1.3 * std::exp(-0.5 * r * r) - 0.3;
  }
  if (w > p.width_max) {
    const double r = (w - p.width_max) / p.width_sigma;
    return 1.3 * std::exp(-0.5 * r * r) - 0.3;
  }
  return 1.0;
}

std::string CentrelineParams::check() const {
  if (!(min_step < search_radius)) return "min_step must be < search_radius";
  if (!(weight_colour + weight_width + weight_angle + weight_step + weight_prediction + weight_crossing > 0.0))
    return "weight_colour, weight_width, weight_angle, weight_step, weight_prediction and weight_crossing must not all be 0";
  if (!(width_min <= width_max)) return "width_max must be >= width_min";
  return "";
}

const char* to_string(CentrelineStatus s) {
  switch (s) {
    case CentrelineStatus::Ok: return "ok";
    case CentrelineStatus::BadParams: return "bad parameters";
    case CentrelineStatus::BadPose: return "bad start pose";
    case CentrelineStatus::NoTriangulation: return "no triangulation";
    case CentrelineStatus::SingleColour: return "single colour";
    case CentrelineStatus::NoPath: return "no path";
  }
  return "?";
}

const char* to_string(CentrelineStop s) {
  switch (s) {
    case CentrelineStop::None: return "not run";
    case CentrelineStop::NoCandidate: return "no candidate above min_reward";
    case CentrelineStop::PoorContinuation: return "no continuation above min_horizon_reward";
    case CentrelineStop::LoopClosed: return "loop closed";
    case CentrelineStop::MaxPoints: return "max_points reached";
    case CentrelineStop::MaxLength: return "max_length reached";
  }
  return "?";
}

CentrelineResult search_centreline(const Triangulation& tri, const std::vector<Cone>& cones,
                                   const Pose2& start, const CentrelineParams& params) {
  CentrelineResult out;
  if (const std::string bad = params::validate(params); !bad.empty()) {
    out.status = CentrelineStatus::BadParams;
    out.reason = "centreline: " + bad;
    return out;
  }
  if (!(finite(start.x) && finite(start.y) && finite(start.yaw))) {
    out.status = CentrelineStatus::BadPose;
    out.reason = "centreline: the start pose is not finite";
    return out;
  }
  if (!tri.ok()) {
    out.status = CentrelineStatus::NoTriangulation;
    out.reason = "centreline: " + (tri.reason.empty() ? std::string("no triangulation") : tri.reason);
    return out;
  }
  // the triangulation must be of these cones
  for (const TriEdge& e : tri.edges) {
    if (e.a >= cones.size() || e.b >= cones.size()) {
      out.status = CentrelineStatus::NoTriangulation;
      out.reason = "centreline: the triangulation is not of these cones (index out of range)";
      return out;
    }
  }
  // one known colour and nothing else: only one boundary was seen
  std::array<std::size_t, 5> count{};
  std::size_t finite_cones = 0;
  for (std::size_t i = 0; i < cones.size(); ++i) {
    if (i < tri.representative.size() && tri.representative[i] != i) continue;
    ++count[static_cast<std::size_t>(cones[i].color)];
    ++finite_cones;
  }
  for (ConeColor c : {ConeColor::Blue, ConeColor::Yellow, ConeColor::SmallOrange,
                      ConeColor::BigOrange}) {
    if (count[static_cast<std::size_t>(c)] == finite_cones) {
      out.status = CentrelineStatus::SingleColour;
      out.reason = "centreline: all " + std::to_string(finite_cones) + " cones are " +
                   std::string(cone_tag(c)) + ": only one boundary, no track to follow";
      return out;
    }
  }
  Search search(tri, cones, params);
  return search.run(start);
}

}  // namespace paddock::planning
