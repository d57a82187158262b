#include "sim/runner/perception_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <tuple>

namespace paddock::runner {
namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
double ratio(long a, long b) { return b > 0 ? static_cast<double>(a) / static_cast<double>(b) : kNaN; }
}  // namespace

double RangeBinStats::precision() const { return ratio(detections_matched, detections); }
double RangeBinStats::recall() const { return ratio(visible_matched, visible); }
double RangeBinStats::colour_accuracy() const { return ratio(colour_right, detections_matched); }
double RangeBinStats::error_mean() const { return error_count > 0 ? error_sum / static_cast<double>(error_count) : kNaN; }

PerceptionMetrics::PerceptionMetrics(std::vector<double> edges, double match_radius) : match_radius_(match_radius) {
  if (edges.empty() || !std::is_sorted(edges.begin(), edges.end()) ||
      std::adjacent_find(edges.begin(), edges.end()) != edges.end())
    throw std::invalid_argument("PerceptionMetrics: bin edges must be strictly increasing");
  for (std::size_t i = 0; i < edges.size(); ++i) {
    RangeBinStats b;
    b.range_min = edges[i];
    b.range_max = i + 1 < edges.size() ? edges[i + 1] : std::numeric_limits<double>::infinity();
    bins_.push_back(b);
  }
}

std::size_t PerceptionMetrics::bin_of(double range) const {
  std::size_t i = 0;
  while (i + 1 < bins_.size() && range >= bins_[i + 1].range_min) ++i;
  return i;
}

void PerceptionMetrics::add(const hal::ConeDetections& perceived, const Pose2& base_pose, Vec2 sensor_in_base,
                            const std::vector<Cone>& truth, const std::vector<bool>& visible) {
  ++frames_;
  const Vec2 sensor = base_pose.transform(sensor_in_base);
  std::vector<Vec2>& seen = seen_;
  seen.resize(perceived.cones.size());
  for (std::size_t i = 0; i < seen.size(); ++i) seen[i] = base_pose.transform(perceived.cones[i].position);

  // the true cones within the radius of the frame's bounding box (a frame
  // sees a small part of the track), then the candidate pairs within the
  // radius, nearest first
  Box frame;
  for (const Vec2& p : seen) frame.add(p);
  std::vector<std::size_t>& near = near_;
  near.clear();
  for (std::size_t j = 0; j < truth.size(); ++j)
    if (frame.near(truth[j].position, match_radius_)) near.push_back(j);
  auto& pairs = pairs_;
  pairs.clear();
  for (std::size_t i = 0; i < seen.size(); ++i) {
    if (!std::isfinite(seen[i].x) || !std::isfinite(seen[i].y)) continue;
    for (const std::size_t j : near) {
      // (a coordinate apart by more than the radius is out: hypot is never
      // below either one; most of the track's cones are, and hypot is slow)
      const Vec2 e = seen[i] - truth[j].position;
      if (std::abs(e.x) > match_radius_ || std::abs(e.y) > match_radius_) continue;
      const double d = norm(e);
      if (d <= match_radius_) pairs.emplace_back(d, i, j);
    }
  }
  std::sort(pairs.begin(), pairs.end());
  std::vector<long>& match_of_seen = match_of_seen_;
  match_of_seen.assign(seen.size(), -1);
  std::vector<char>& truth_taken = truth_taken_;
  truth_taken.assign(truth.size(), 0);
  for (const auto& [d, i, j] : pairs) {
    if (match_of_seen[i] >= 0 || truth_taken[j]) continue;
    match_of_seen[i] = static_cast<long>(j);
    truth_taken[j] = 1;
  }

  for (std::size_t i = 0; i < seen.size(); ++i) {
    const long j = match_of_seen[i];
    const Vec2 at = j >= 0 ? truth[static_cast<std::size_t>(j)].position : seen[i];
    if (!std::isfinite(at.x) || !std::isfinite(at.y)) continue;
    RangeBinStats& b = bins_[bin_of(distance(sensor, at))];
    ++b.detections;
    if (j < 0) continue;
    const Cone& t = truth[static_cast<std::size_t>(j)];
    ++b.detections_matched;
    if (perceived.cones[i].color == t.color) ++b.colour_right;
    if (perceived.cones[i].color == ConeColor::Unknown) ++b.colour_unknown;
    const double e = distance(seen[i], t.position);
    b.error_sum += e;
    b.error_max = std::max(b.error_max, e);
    ++b.error_count;
  }
  for (std::size_t j = 0; j < truth.size(); ++j) {
    if (!visible.empty() && !visible[j]) continue;
    RangeBinStats& b = bins_[bin_of(distance(sensor, truth[j].position))];
    ++b.visible;
    if (truth_taken[j]) ++b.visible_matched;
  }
}

RangeBinStats PerceptionMetrics::total() const {
  RangeBinStats t;
  t.range_min = bins_.front().range_min;
  t.range_max = bins_.back().range_max;
  for (const RangeBinStats& b : bins_) {
    t.detections += b.detections;
    t.detections_matched += b.detections_matched;
    t.visible += b.visible;
    t.visible_matched += b.visible_matched;
    t.colour_right += b.colour_right;
    t.colour_unknown += b.colour_unknown;
    t.error_sum += b.error_sum;
    t.error_max = std::max(t.error_max, b.error_max);
    t.error_count += b.error_count;
  }
  return t;
}

}  // namespace paddock::runner
