#include "autonomy/perception/clustering.h"

#include <algorithm>
#include <random>
#include <set>
#include <vector>

#include <gtest/gtest.h>

namespace paddock::perception {
namespace {

// single linkage by brute force: a breadth-first search over all pairs
std::vector<std::set<std::uint32_t>> brute_force(const Cloud& cloud, double tol, double max_range, double mx, double my) {
  std::vector<std::uint32_t> in;
  for (std::uint32_t i = 0; i < cloud.points.size(); ++i) {
    const CloudPoint& p = cloud.points[i];
    const double dx = p.x - mx, dy = p.y - my;
    if (p.label == PointLabel::NonGround && dx * dx + dy * dy <= max_range * max_range) in.push_back(i);
  }
  std::vector<bool> seen(in.size(), false);
  std::vector<std::set<std::uint32_t>> out;
  for (std::size_t s = 0; s < in.size(); ++s) {
    if (seen[s]) continue;
    std::vector<std::size_t> queue{s};
    seen[s] = true;
    std::set<std::uint32_t> members;
    for (std::size_t h = 0; h < queue.size(); ++h) {
      const CloudPoint& a = cloud.points[in[queue[h]]];
      members.insert(in[queue[h]]);
      for (std::size_t j = 0; j < in.size(); ++j) {
        if (seen[j]) continue;
        const CloudPoint& b = cloud.points[in[j]];
        const double dx = static_cast<double>(a.x) - b.x, dy = static_cast<double>(a.y) - b.y;
        if (dx * dx + dy * dy <= tol * tol) {
          seen[j] = true;
          queue.push_back(j);
        }
      }
    }
    out.push_back(members);
  }
  return out;
}

TEST(Clustering, SamePartitionAsBruteForceSingleLinkage) {
  // blobs of random size and spread (some touching, some chains), ground
  // points mixed in, a few points out of range
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    Cloud cloud;
    const int blobs = 5 + static_cast<int>(u(rng) * 30);
    for (int b = 0; b < blobs; ++b) {
      const double cx = -30.0 + 60.0 * u(rng), cy = -30.0 + 60.0 * u(rng);
      const double spread = 0.05 + 0.6 * u(rng);
      const int n = 1 + static_cast<int>(u(rng) * 120);
      for (int k = 0; k < n; ++k) {
        CloudPoint p;
        p.x = static_cast<float>(cx + spread * (u(rng) - 0.5));
        p.y = static_cast<float>(cy + spread * (u(rng) - 0.5));
        p.label = u(rng) < 0.1 ? PointLabel::Ground : PointLabel::NonGround;
        cloud.points.push_back(p);
      }
    }
    ClusteringParams params;
    params.tolerance = 0.2 + 0.4 * u(rng);
    const LidarCalibration calib;
    Clusterer clusterer(params, calib);
    Clusters got;
    const ClusteringStats stats = clusterer.cluster(cloud, got);
    const auto want = brute_force(cloud, params.tolerance, params.max_range, calib.mount_x, calib.mount_y);
    std::set<std::set<std::uint32_t>> got_sets, want_sets(want.begin(), want.end());
    for (std::size_t k = 0; k < got.size(); ++k)
      got_sets.insert(std::set<std::uint32_t>(got.members.begin() + got.offsets[k], got.members.begin() + got.offsets[k + 1]));
    EXPECT_EQ(got_sets, want_sets) << "trial " << trial;
    EXPECT_EQ(stats.clusters, want.size());
  }
}

TEST(Clustering, PointsJustInsideAndOutsideTheTolerance) {
  Cloud cloud;
  auto add = [&](float x, float y) {
    CloudPoint p;
    p.x = x;
    p.y = y;
    cloud.points.push_back(p);
  };
  // a chain 0.39 m apart: one cluster; then a gap of 0.41 m: a second
  add(5.0f, 0.0f);
  add(5.39f, 0.0f);
  add(5.78f, 0.0f);
  add(6.19f, 0.0f);
  ClusteringParams params;
  params.tolerance = 0.4;
  Clusterer clusterer(params, LidarCalibration{});
  Clusters got;
  clusterer.cluster(cloud, got);
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got.offsets[1], 3u);
}

}  // namespace
}  // namespace paddock::perception
