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
  // near the midpoint (the edge's own two count double); 0 when none. Set
  // with the edge's cone list, the first time the search needs either
  // (Search::near_cones)
  double colour_a_left = 0.0;
  // the part of that average that is against the edge whichever way it is
  // crossed: its two cones of one colour (a boundary, or the strip between
  // two lanes), <= 0
  double colour_against = 0.0;
};

// the factors of a step onto an edge's midpoint that do not depend on the
// heading the step comes from: its direction, the colour, the track width,
// the step length and the crossing (Search::step_terms)
struct StepTerms {
  Vec2 u;  // unit direction of the step
  double colour = 0.0;
  double width = 0.0;
  double step = 0.0;
  double crossing = 0.0;
};

// a step from one edge's midpoint onto a neighbouring edge's (an entry of
// the edge's neighbour list), and what the search has learnt of it so far.
// Every node standing on an edge stands on its midpoint (Node::p is set from
// EdgeInfo::mid and nothing else), so d, l, the factors of StepTerms and
// the clearance test are functions of the two edges alone: computed once
// per cycle, with the same operations on the same operands as for the
// first node that needs them, they are bit for bit what every later node
// would compute again.
struct Step {
  std::size_t to = 0;        // the edge stepped onto
  Vec2 d;                    // its midpoint minus the one stepped from
  double l = 0.0;            // |d| (sqrt of the squared norm, as score has it)
  bool has_terms = false;    // `terms` is filled in
  signed char clear = -1;    // the clearance test: -1 not run yet, 0 fails, 1 passes
  StepTerms terms;
};

constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
// no floor under the rewards a caller wants (Search::candidate)
constexpr double kNoFloor = -std::numeric_limits<double>::infinity();

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
  std::size_t step = kNone;  // its entry in the neighbour list of the node's edge; none from the vehicle
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

// the search's working memory: its lists are kept from one call to the
// next on the same thread (search_centreline), so that a planning cycle
// reuses the capacity of the last one instead of allocating (and faulting
// in) a few hundred kilobytes afresh. Every list is emptied or overwritten
// before it is read.
struct SearchScratch {
  std::vector<EdgeInfo> info;
  std::vector<char> used;
  std::vector<std::size_t> edge_a, edge_b;
  std::vector<std::pair<std::pair<std::int64_t, std::int64_t>, std::size_t>> mid_keyed, cone_keyed;
  std::vector<std::size_t> nb_first, nb_count;
  std::vector<Step> steps;
  std::vector<Vec2> cone_pos;
  std::vector<std::size_t> cone_index, cone_first, cone_count, cone_list;
  std::vector<std::vector<Candidate>> buffers;
};

class Search {
 public:
  Search(const Triangulation& tri, const std::vector<Cone>& cones, const CentrelineParams& p, SearchScratch& m)
      : p_(p), cones_(cones), info_(m.info), used_(m.used), edge_a_(m.edge_a), edge_b_(m.edge_b),
        mid_keyed_(m.mid_keyed), nb_first_(m.nb_first), nb_count_(m.nb_count), steps_(m.steps),
        cone_pos_(m.cone_pos), cone_index_(m.cone_index), cone_keyed_(m.cone_keyed), cone_first_(m.cone_first),
        cone_count_(m.cone_count), cone_list_(m.cone_list), buffers_(m.buffers) {
    const double wsum = p.weight_colour + p.weight_width + p.weight_angle + p.weight_step +
                        p.weight_prediction + p.weight_crossing;
    inv_weight_sum_ = 1.0 / wsum;
    cos_max_turn_ = std::cos(p.max_turn);
    cos_closure_ = std::cos(p.closure_max_angle);
    // what each edge brings by itself
    info_.assign(tri.edges.size(), EdgeInfo{});
    edge_a_.clear();
    edge_b_.clear();
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
    sort_midpoints();
    sort_cones(tri);
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
  // cell coordinates of a square grid, clamped so that far-away cones
  // cannot overflow
  static std::int64_t cell_index(double v, double cell) {
    return static_cast<std::int64_t>(std::clamp(std::floor(v / cell), -1e15, 1e15));
  }

  // the midpoints sorted into square cells of the search radius, for the
  // neighbour lists (neighbours)
  void sort_midpoints() {
    const std::size_t n = info_.size();
    mid_keyed_.resize(n);
    for (std::size_t i = 0; i < n; ++i)
      mid_keyed_[i] = {{cell_index(info_[i].mid.x, p_.search_radius), cell_index(info_[i].mid.y, p_.search_radius)}, i};
    std::sort(mid_keyed_.begin(), mid_keyed_.end());
    nb_first_.assign(n, kNone);
    nb_count_.assign(n, 0);
    steps_.clear();
  }

  // the steps from edge i's midpoint onto the midpoints within the search
  // radius of it (in steps_ from nb_first_[i], nb_count_[i] of them), found
  // the first time a node on edge i is expanded: of the ~330 edges of a
  // partial autocross map about 50 are ever expanded in a cycle. Midpoints
  // nearer than min_step are left out: score() would refuse them, and
  // nothing else reads the list. The order is that of the cells, then of
  // the edges' indices, as it has always been (the search's choices do not
  // depend on it: collect sorts, best_step takes a maximum)
  void neighbours(std::size_t i) {
    if (nb_first_[i] != kNone) return;
    const std::size_t n = info_.size();
    const double r2 = p_.search_radius * p_.search_radius;
    const double min2 = p_.min_step * p_.min_step;
    const Vec2 m = info_[i].mid;
    const std::int64_t cx = cell_index(m.x, p_.search_radius), cy = cell_index(m.y, p_.search_radius);
    nb_first_[i] = steps_.size();
    for (std::int64_t dx = -1; dx <= 1; ++dx) {
      const auto lo = std::make_pair(std::make_pair(cx + dx, cy - 1), std::size_t{0});
      const auto hi = std::make_pair(std::make_pair(cx + dx, cy + 1), n);
      auto it = std::lower_bound(mid_keyed_.begin(), mid_keyed_.end(), lo);
      const auto end = std::upper_bound(it, mid_keyed_.end(), hi);
      for (; it != end; ++it) {
        const std::size_t j = it->second;
        if (j == i) continue;
        // d and its squared norm exactly as score() has them for a node on edge i
        const Vec2 d = info_[j].mid - m;
        const double l2 = squared_norm(d);
        if (l2 < min2 || l2 > r2) continue;
        Step st;
        st.to = j;
        st.d = d;
        st.l = std::sqrt(l2);
        steps_.push_back(st);
      }
    }
    nb_count_[i] = steps_.size() - nb_first_[i];
  }

  // the triangulated cones, and the same sorted into square cells (for
  // near_cones)
  void sort_cones(const Triangulation& tri) {
    cone_pos_.clear();
    cone_index_.clear();
    for (std::size_t i = 0; i < cones_.size(); ++i)
      if (i < tri.representative.size() && tri.representative[i] == i) {
        cone_pos_.push_back(cones_[i].position);
        cone_index_.push_back(i);
      }
    reach_list_ = 0.5 * p_.search_radius + p_.min_clearance;
    cone_cell_ = std::max(std::max(reach_list_, p_.colour_radius), 1.0);
    cone_keyed_.resize(cone_pos_.size());
    for (std::size_t i = 0; i < cone_pos_.size(); ++i)
      cone_keyed_[i] = {{cell_index(cone_pos_[i].x, cone_cell_), cell_index(cone_pos_[i].y, cone_cell_)}, i};
    std::sort(cone_keyed_.begin(), cone_keyed_.end());
    cone_first_.assign(info_.size(), kNone);
    cone_count_.assign(info_.size(), 0);
    cone_list_.clear();
  }

  // one pass over the cones near edge e's midpoint, the first time the
  // search needs it (a step onto e is scored, or one from or onto it is
  // tested for clearance):
  //  - the cones within search_radius / 2 + min_clearance (cone_list_ from
  //    cone_first_[e]): a cone closer than min_clearance to a step between
  //    two midpoints at most search_radius apart is in the list of one of
  //    them;
  //  - the colour evidence (EdgeInfo::colour_a_left): a blue cone on cone
  //    a's side of the midpoint, or a yellow one on b's side, says a's side
  //    is the left one. A neighbour's side is that of its projection onto
  //    the edge (cones near the perpendicular bisector say nothing); the
  //    edge's own cones count double, and one colour on both of them (a
  //    boundary, or the strip between two lanes) counts against either way.
  //    Averaged over several cones, one swapped colour does not turn a
  //    boundary into a rung.
  // Each edge's pass is independent of the others', so doing it on demand
  // gives the same lists and the same sums in the same order.
  void near_cones(std::size_t e) {
    if (cone_first_[e] != kNone) return;
    const std::vector<Cone>& cones = cones_;
    const double list2 = reach_list_ * reach_list_, colour2 = p_.colour_radius * p_.colour_radius;
    auto coloured = [](ConeColor c) { return c == ConeColor::Blue || c == ConeColor::Yellow; };
    auto vote = [](ConeColor c, bool a_side) { return (c == ConeColor::Blue) == a_side ? 1.0 : -1.0; };
    EdgeInfo& in = info_[e];
    const Vec2 m = in.mid;
    const std::size_t ia = edge_a_[e], ib = edge_b_[e];
    double sum = 0.0, against = 0.0, weight = 0.0;
    const bool same = coloured(cones[ia].color) && cones[ia].color == cones[ib].color;
    for (std::size_t i : {ia, ib}) {
      if (!coloured(cones[i].color)) continue;
      if (same) {
        against -= 2.0;
      } else {
        sum += 2.0 * vote(cones[i].color, i == ia);
      }
      weight += 2.0;
    }
    cone_first_[e] = cone_list_.size();
    const std::int64_t cx = cell_index(m.x, cone_cell_), cy = cell_index(m.y, cone_cell_);
    for (std::int64_t dx = -1; dx <= 1; ++dx) {
      const auto lo = std::make_pair(std::make_pair(cx + dx, cy - 1), std::size_t{0});
      const auto hi = std::make_pair(std::make_pair(cx + dx, cy + 1), cone_pos_.size());
      auto it = std::lower_bound(cone_keyed_.begin(), cone_keyed_.end(), lo);
      const auto end = std::upper_bound(it, cone_keyed_.end(), hi);
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
    in.colour_against = weight > 0.0 ? against / weight : 0.0;
    cone_count_[e] = cone_list_.size() - cone_first_[e];
  }

  // true when the step of candidate c from s (a midpoint) onto its edge's
  // midpoint keeps min_clearance from every cone: it does not cut through a
  // boundary. Between two midpoints the answer is kept in the step
  bool clear(const Node& s, const Candidate& c) {
    if (s.edge == kNoCone) return clear_all(s, c.edge);
    signed char& known = steps_[c.step].clear;
    if (known < 0) known = clear_between(s.edge, c.edge) ? 1 : 0;
    return known == 1;
  }

  // the step between the midpoints of edges a and b against the cones near either
  bool clear_between(std::size_t a, std::size_t b) {
    near_cones(a);
    near_cones(b);
    const double c2 = p_.min_clearance * p_.min_clearance;
    const Vec2 from = info_[a].mid, to = info_[b].mid;
    auto near = [&](std::size_t i) {
      const Vec2 q = cone_pos_[i];
      return squared_norm(q - closest_on_segment(from, to, q)) < c2;
    };
    for (std::size_t k = cone_first_[a]; k < cone_first_[a] + cone_count_[a]; ++k)
      if (near(cone_list_[k])) return false;
    for (std::size_t k = cone_first_[b]; k < cone_first_[b] + cone_count_[b]; ++k)
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

  // the factors of the step d (of length l) onto edge c's midpoint that do
  // not depend on the heading it comes from
  StepTerms step_terms(Vec2 d, double l, std::size_t c) {
    near_cones(c);  // the colour evidence
    const EdgeInfo& e = info_[c];
    StepTerms t;
    t.u = d / l;
    // colour: blue on the left and yellow on the right of the step
    t.colour = (cross(t.u, e.a - e.mid) > 0.0 ? e.colour_a_left : -e.colour_a_left) + e.colour_against;
    // the track width: the edge's extent across the direction of travel (a
    // diagonal rung between staggered cones is longer than the track is wide)
    const double across_edge = std::abs(cross(t.u, e.dir));
    t.width = track_width_reward(e.length * across_edge, p_);
    t.step = bell(l - p_.step_preferred, p_.step_sigma);
    // a track crossing (rung) is crossed squarely, a boundary edge lengthwise
    t.crossing = 2.0 * across_edge - 1.0;
    return t;
  }

  // the reward of stepping from s onto edge c's midpoint (`step`: the entry
  // of c in the neighbour list of s's edge, kNone from the vehicle); false
  // when the midpoint is not a candidate (too near, too far, outside the
  // forward cone), and when its reward cannot reach min_reward or exceed
  // `floor` (the callers would drop it)
  bool score(const Node& s, std::size_t c, std::size_t step, double floor, Candidate& out) {
    const EdgeInfo& e = info_[c];
    Vec2 d;
    double l = 0.0;
    if (step == kNone) {
      d = e.mid - s.p;
      const double l2 = squared_norm(d);
      if (l2 < p_.min_step * p_.min_step || l2 > p_.search_radius * p_.search_radius) return false;
      l = std::sqrt(l2);
    } else {
      // the neighbour list holds only midpoints in range
      d = steps_[step].d;
      l = steps_[step].l;
    }
    const double along = dot(s.dir, d);
    if (along < cos_max_turn_ * l) return false;
    const double across = cross(s.dir, d);
    StepTerms fresh;
    const StepTerms* st = &fresh;
    if (step == kNone) {
      fresh = step_terms(d, l, c);
    } else {
      Step& known = steps_[step];
      if (!known.has_terms) {
        known.terms = step_terms(d, l, c);
        known.has_terms = true;
      }
      st = &known.terms;
    }
    // the reward with the angle and prediction factors at their largest (1;
    // bell() <= 1) bounds the reward from above: the weights are >= 0 and
    // rounding is monotonic, so the same sum below cannot come out larger.
    // A step it rules out needs neither atan2 nor the prediction
    const double bound = (p_.weight_colour * st->colour + p_.weight_width * st->width +
                          p_.weight_angle * 1.0 + p_.weight_step * st->step +
                          p_.weight_prediction * 1.0 + p_.weight_crossing * st->crossing) *
                         inv_weight_sum_;
    if (bound < p_.min_reward || bound <= floor) return false;
    RewardTerms t;
    t.colour = st->colour;
    t.width = st->width;
    const double turn = std::atan2(across, along);
    t.angle = bell(turn, p_.angle_sigma);
    t.step = st->step;
    // the prediction: the heading turned as much again as over the last two
    // steps on average (the midpoints zig-zag), at this candidate's distance
    const Vec2 predicted = s.p + s.pred_dir * l;
    t.prediction = bell(plain_norm(e.mid - predicted), p_.prediction_sigma);
    t.crossing = st->crossing;
    out.edge = c;
    out.step = step;
    out.terms = t;
    out.reward = (p_.weight_colour * t.colour + p_.weight_width * t.width +
                  p_.weight_angle * t.angle + p_.weight_step * t.step +
                  p_.weight_prediction * t.prediction + p_.weight_crossing * t.crossing) *
                 inv_weight_sum_;
    out.next.p = e.mid;
    out.next.dir = st->u;
    out.next.turn = 0.5 * (turn + s.last_turn);
    out.next.last_turn = turn;
    out.next.edge = c;
    out.closes = false;
    out.target = -1;
    return true;
  }

  // the best `keep` candidates from s above min_reward that keep clear of
  // the cones, best first
  void collect(const Node& s, const Branch& branch, int keep, std::vector<Candidate>& out) {
    out.clear();
    Candidate c;
    if (s.edge == kNoCone) {
      for (std::size_t j = 0; j < info_.size(); ++j)
        if (candidate(s, j, kNone, branch, kNoFloor, c)) out.push_back(c);
    } else {
      neighbours(s.edge);
      const std::size_t first = nb_first_[s.edge], last = first + nb_count_[s.edge];
      for (std::size_t k = first; k < last; ++k)
        if (candidate(s, steps_[k].to, k, branch, kNoFloor, c)) out.push_back(c);
    }
    // best first; ties by edge index so the order never depends on the sort
    std::sort(out.begin(), out.end(), [](const Candidate& x, const Candidate& y) {
      return x.reward > y.reward || (x.reward == y.reward && x.edge < y.edge);
    });
    // the clearance test last (it is the costly one), best first, until the beam is full
    std::size_t n = 0;
    for (std::size_t k = 0; k < out.size() && n < static_cast<std::size_t>(keep); ++k) {
      if (clear(s, out[k])) out[n++] = out[k];
    }
    out.resize(n);
  }

  // scores edge j (`step`: its entry in the neighbour list of s's edge) as
  // the next step from s into c: false when it is no candidate (reused, too
  // near or far, outside the forward cone, below min_reward), or when its
  // reward is not above `floor`; the clearance is not tested here
  bool candidate(const Node& s, std::size_t j, std::size_t step, const Branch& branch, double floor,
                 Candidate& c) {
    if (j == s.edge || branch.contains(j)) return false;
    int target = -1;
    if (used_[j]) {
      // a used edge is taken again only to close the lap
      if (!closure_ok_ || path_length_ < p_.closure_min_length) return false;
      for (int k = 0; k < p_.closure_points; ++k)
        if ((*first_points_)[static_cast<std::size_t>(k)].edge == j) target = k;
      if (target < 0) return false;
    }
    if (!score(s, j, step, floor, c) || !(c.reward >= p_.min_reward)) return false;
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
  double best_step(const Node& s, const Branch& branch) {
    double best = 0.0;
    Candidate c;
    neighbours(s.edge);
    const std::size_t first = nb_first_[s.edge], last = first + nb_count_[s.edge];
    for (std::size_t k = first; k < last; ++k) {
      if (!candidate(s, steps_[k].to, k, branch, best, c) || c.reward <= best) continue;
      if (clear(s, c)) best = c.reward;
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

  using Keyed = std::vector<std::pair<std::pair<std::int64_t, std::int64_t>, std::size_t>>;
  const CentrelineParams& p_;
  const std::vector<Cone>& cones_;
  // the lists live in a SearchScratch
  std::vector<EdgeInfo>& info_;
  std::vector<char>& used_;
  std::vector<std::size_t>& edge_a_;  // each edge's cones (input indices)
  std::vector<std::size_t>& edge_b_;
  // the neighbour lists, built on demand (neighbours)
  Keyed& mid_keyed_;                    // the midpoints by cell
  std::vector<std::size_t>& nb_first_;  // per edge, its steps in steps_ (kNone: not built)
  std::vector<std::size_t>& nb_count_;
  std::vector<Step>& steps_;
  // the cones near each edge, on demand (near_cones)
  std::vector<Vec2>& cone_pos_;           // the triangulated cones
  std::vector<std::size_t>& cone_index_;  // their indices in the input
  Keyed& cone_keyed_;                     // the same by cell
  std::vector<std::size_t>& cone_first_;  // per edge, its cones in cone_list_ (kNone: not yet)
  std::vector<std::size_t>& cone_count_;
  std::vector<std::size_t>& cone_list_;
  std::vector<std::vector<Candidate>>& buffers_;  // one per look-ahead level
  double reach_list_ = 0.0, cone_cell_ = 1.0;
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
  thread_local SearchScratch scratch;
  Search search(tri, cones, params, scratch);
  return search.run(start);
}

}  // namespace paddock::planning
