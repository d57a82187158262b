// the hashed voxel map of the LiDAR-inertial odometry, against independent
// truth: a brute-force search over the points the down-sampling rule keeps
// (each leaf's inserted point nearest its centre, found with an ordered map),
// the reach's sphere point by point, and its behaviour on bad input
#include "autonomy/slam/voxel_map.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <new>
#include <random>
#include <stdexcept>
#include <vector>

// every allocation of this test binary is counted (the knn test asks that a
// query allocates nothing); otherwise malloc and free as usual. GCC sees
// free() meet a pointer from operator new where it inlines a delete, and
// does not know that operator new is this malloc
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
namespace {
std::atomic<long> g_allocations{0};
}  // namespace
void* operator new(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
// the nothrow pair too (std::stable_sort's buffer): whatever this binary's
// deletes free must come from this malloc (AddressSanitizer, which has its
// own nothrow new, reported the mismatch)
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(n == 0 ? 1 : n);
}
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }

namespace paddock::slam {
namespace {

using Vec3 = Eigen::Vector3d;
using Neighbour = VoxelMap::Neighbour;

// a number as the map stores it: rounded to float. Through a volatile:
// GCC 12.2 at -O2 and -O3 (SLP vectoriser) compiles the plain double ->
// float -> double round trip of two neighbouring coordinates into a copy
// when the result lands in a local aggregate (an Eigen vector, an array),
// so `Vec3{float(x), float(y), float(z)}` comes back with x and y unrounded
double to_float(double x) {
  volatile float f = static_cast<float>(x);
  return f;
}
Vec3 rounded(const Vec3& p) { return {to_float(p.x()), to_float(p.y()), to_float(p.z())}; }

double dist2(const Vec3& a, const Vec3& b) {
  const double dx = a.x() - b.x(), dy = a.y() - b.y(), dz = a.z() - b.z();
  return (dx * dx + dy * dy) + dz * dz;
}

bool lexicographic_less(const Vec3& a, const Vec3& b) {
  return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
}

// uniform points in [lo, hi), float-exact
std::vector<Vec3> random_cloud(std::mt19937_64& rng, std::size_t n, const Vec3& lo, const Vec3& hi) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Vec3> pts;
  for (std::size_t i = 0; i < n; ++i) {
    const double x = u(rng), y = u(rng), z = u(rng);
    pts.push_back(rounded({lo.x() + x * (hi.x() - lo.x()), lo.y() + y * (hi.y() - lo.y()), lo.z() + z * (hi.z() - lo.z())}));
  }
  return pts;
}

std::vector<Vec3> sorted(std::vector<Vec3> pts) {
  std::sort(pts.begin(), pts.end(), lexicographic_less);
  return pts;
}

// the down-sampling rule on its own: per leaf (floor(p / leaf) on each
// axis), the inserted point nearest the leaf's centre, the first of equals;
// sorted by (x, y, z)
std::vector<Vec3> downsampled(const std::vector<Vec3>& inserted, double leaf) {
  std::map<std::array<long long, 3>, std::pair<Vec3, double>> leaves;
  for (const Vec3& in : inserted) {
    const Vec3 p = rounded(in);
    std::array<long long, 3> key;
    Vec3 centre;
    for (int a = 0; a < 3; ++a) {
      key[static_cast<std::size_t>(a)] = static_cast<long long>(std::floor(p[a] / leaf));
      centre[a] = (static_cast<double>(key[static_cast<std::size_t>(a)]) + 0.5) * leaf;
    }
    const double d2 = dist2(p, centre);
    const auto it = leaves.find(key);
    if (it == leaves.end()) leaves.emplace(key, std::make_pair(p, d2));
    else if (d2 < it->second.second) it->second = {p, d2};
  }
  std::vector<Vec3> kept;
  for (const auto& [key, value] : leaves) kept.push_back(value.first);
  return sorted(kept);
}

// the k nearest of pts within max_distance, by (distance, x, y, z)
std::vector<Neighbour> brute_knn(const std::vector<Vec3>& pts, const Vec3& q, int k, double max_distance) {
  std::vector<Neighbour> all;
  for (const Vec3& p : pts) {
    const double d2 = dist2(p, q);
    if (d2 <= max_distance * max_distance) all.push_back({p, d2});
  }
  std::sort(all.begin(), all.end(), [](const Neighbour& a, const Neighbour& b) {
    return a.distance2 != b.distance2 ? a.distance2 < b.distance2 : lexicographic_less(a.point, b.point);
  });
  if (all.size() > static_cast<std::size_t>(k)) all.resize(static_cast<std::size_t>(k));
  return all;
}

void expect_same(const std::vector<Neighbour>& got, const std::vector<Neighbour>& want, const char* what) {
  ASSERT_EQ(got.size(), want.size()) << what;
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].point, want[i].point) << what << " #" << i;
    EXPECT_EQ(got[i].distance2, want[i].distance2) << what << " #" << i;
  }
}

TEST(VoxelMap, DownSamplingKeepsEachLeafsPointNearestItsCentre) {
  // a dense cloud (about 5 points per leaf) inserted in five calls
  std::mt19937_64 rng(11);
  const std::vector<Vec3> cloud = random_cloud(rng, 20000, {-1.0, -1.0, -0.5}, {1.0, 1.0, 0.5});
  VoxelMapParams params;
  params.max_points_per_voxel = 125;  // a voxel's every leaf
  VoxelMap map(params);
  VoxelMap::InsertResult total;
  for (std::size_t b = 0; b < 5; ++b) {
    const std::vector<Vec3> batch(cloud.begin() + static_cast<long>(b * 4000), cloud.begin() + static_cast<long>((b + 1) * 4000));
    const VoxelMap::InsertResult r = map.insert(batch);
    EXPECT_EQ(r.added + r.replaced + r.skipped + r.full + r.rejected, 4000);
    total.added += r.added;
    total.replaced += r.replaced;
    total.full += r.full;
    total.rejected += r.rejected;
  }
  EXPECT_EQ(total.full, 0);
  EXPECT_EQ(total.rejected, 0);
  EXPECT_EQ(map.size(), static_cast<std::size_t>(total.added));
  EXPECT_GT(total.replaced, 1000);

  // never two points in one leaf
  const std::vector<Vec3> kept = map.points();
  std::map<std::array<long long, 3>, int> per_leaf;
  for (const Vec3& p : kept)
    ++per_leaf[{static_cast<long long>(std::floor(p.x() / 0.1)), static_cast<long long>(std::floor(p.y() / 0.1)),
                static_cast<long long>(std::floor(p.z() / 0.1))}];
  for (const auto& [leaf, count] : per_leaf) EXPECT_EQ(count, 1);
  // and the one kept is the one nearest the centre
  const std::vector<Vec3> want = downsampled(cloud, 0.1);
  EXPECT_EQ(sorted(kept), want);
  EXPECT_EQ(map.size(), want.size());
}

TEST(VoxelMap, AnInsertReplacesOnlyAPointFartherFromTheLeafsCentre) {
  // binary fractions, so that ties are ties
  VoxelMapParams p;
  p.leaf_size = 0.125;
  VoxelMap map(p);
  // the leaf [0, 0.125)^3, centre (0.0625, 0.0625, 0.0625)
  EXPECT_EQ(map.insert({{0.015625, 0.0625, 0.0625}}).added, 1);
  EXPECT_EQ(map.insert({{0.03125, 0.0625, 0.0625}}).replaced, 1);
  EXPECT_EQ(map.insert({{0.109375, 0.0625, 0.0625}}).skipped, 1);  // 4.7 cm out against 3.1 cm
  EXPECT_EQ(map.insert({{0.09375, 0.0625, 0.0625}}).skipped, 1);   // as near: the first stays
  // the leaf [-0.125, 0)^3 is another one
  EXPECT_EQ(map.insert({{-0.0625, -0.0625, -0.0625}}).added, 1);
  ASSERT_EQ(map.size(), 2u);
  std::vector<Neighbour> out;
  ASSERT_EQ(map.knn({0.25, 0.25, 0.25}, 1, 1.0, out), 1);
  EXPECT_EQ(out[0].point, Vec3(0.03125, 0.0625, 0.0625));
  EXPECT_EQ(map.voxels(), 2u);
}

TEST(VoxelMap, WithoutReplacementALeafKeepsItsFirstPoint) {
  // the LIO's map (replace = false): the same points as above, in a random
  // cloud too; every leaf holds the first point it was given, and only that
  VoxelMapParams p;
  p.leaf_size = 0.125;
  p.replace = false;
  VoxelMap map(p);
  EXPECT_EQ(map.insert({{0.015625, 0.0625, 0.0625}}).added, 1);
  EXPECT_EQ(map.insert({{0.03125, 0.0625, 0.0625}}).skipped, 1);  // nearer the centre, yet the first stays
  std::vector<Neighbour> out;
  ASSERT_EQ(map.knn({0.25, 0.25, 0.25}, 1, 1.0, out), 1);
  EXPECT_EQ(out[0].point, Vec3(0.015625, 0.0625, 0.0625));

  VoxelMapParams q;
  q.replace = false;
  q.max_points_per_voxel = 1000;
  VoxelMap cloud_map(q);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::map<std::array<long long, 3>, Vec3> first;  // brute force: a leaf's first point (as float)
  long replaced = 0;
  for (int batch = 0; batch < 4; ++batch) {
    std::vector<Vec3> pts;
    for (int i = 0; i < 1000; ++i) pts.emplace_back(u(rng), u(rng), u(rng));
    replaced += cloud_map.insert(pts).replaced;
    for (const Vec3& v : pts) {
      const Vec3 r = rounded(v);
      first.emplace(std::array<long long, 3>{static_cast<long long>(std::floor(r.x() / 0.1)),
                                             static_cast<long long>(std::floor(r.y() / 0.1)),
                                             static_cast<long long>(std::floor(r.z() / 0.1))},
                    r);
    }
  }
  EXPECT_EQ(replaced, 0);
  std::vector<Vec3> want;
  for (const auto& [leaf, v] : first) want.push_back(v);
  EXPECT_EQ(sorted(cloud_map.points()), sorted(want));
}

// the leaf is the rounded point's: 0.5 - 1e-12 is stored as 0.5, in the
// leaf [0.5, 0.6) of the point at its centre 0.55 (each axis in turn)
TEST(VoxelMap, DecisionsAreTakenOnThePointRoundedToFloat) {
  for (int a = 0; a < 3; ++a) {
    Vec3 below(0.05, 0.05, 0.05), centre(0.05, 0.05, 0.05);
    below[a] = 0.5 - 1e-12;
    centre[a] = 0.55;
    VoxelMap map;
    EXPECT_EQ(map.insert({below}).added, 1) << a;
    EXPECT_EQ(map.insert({centre}).replaced, 1) << a;
    EXPECT_EQ(map.size(), 1u) << a;
    VoxelMap other;
    other.insert({centre});
    EXPECT_EQ(other.insert({below}).skipped, 1) << a;
    below[a] = 0.5;
    EXPECT_EQ(other.insert({below}).skipped, 1) << a;
    EXPECT_EQ(other.points(), std::vector<Vec3>{rounded(centre)}) << a;
  }
}

TEST(VoxelMap, AFullVoxelTakesNoMorePoints) {
  VoxelMapParams p;
  p.max_points_per_voxel = 3;
  VoxelMap map(p);
  const VoxelMap::InsertResult r =
      map.insert({{0.05, 0.05, 0.05}, {0.15, 0.05, 0.05}, {0.25, 0.05, 0.05}, {0.35, 0.05, 0.05}, {0.45, 0.05, 0.05}});
  EXPECT_EQ(r.added, 3);
  EXPECT_EQ(r.full, 2);
  EXPECT_EQ(map.size(), 3u);
  // a point of a leaf it holds still competes for that leaf
  EXPECT_EQ(map.insert({{0.151, 0.05, 0.05}}).skipped, 1);
}

// knn against brute force: exact with the 26 neighbours whenever
// max_distance <= voxel_size, for several k, on a sparse and a dense cloud
TEST(VoxelMap, KnnIsExactWithinAVoxelWithAllNeighbours) {
  std::mt19937_64 rng(5);
  for (const double side : {10.0, 2.0}) {
    const std::vector<Vec3> cloud = random_cloud(rng, 20000, {-side, -side, -0.2 * side}, {side, side, 0.2 * side});
    VoxelMapParams params;  // nearby26 by default
    params.max_points_per_voxel = 125;  // the dense cloud fills whole voxels
    VoxelMap map(params);
    map.insert(cloud);
    const std::vector<Vec3> truth = downsampled(cloud, 0.1);
    ASSERT_EQ(map.size(), truth.size());
    const std::vector<Vec3> queries = random_cloud(rng, 500, {-side - 0.5, -side - 0.5, -0.2 * side - 0.5},
                                                   {side + 0.5, side + 0.5, 0.2 * side + 0.5});
    std::vector<Neighbour> out;
    for (const int k : {1, 5, 20})
      for (const double max_distance : {0.15, 0.3, 0.5}) {
        int found = 0;
        for (const Vec3& q : queries) {
          const int n = map.knn(q, k, max_distance, out);
          EXPECT_EQ(n, static_cast<int>(out.size()));
          expect_same(out, brute_knn(truth, q, k, max_distance), "knn");
          found += n;
        }
        EXPECT_GT(found, 0);
      }
  }
}

// the recall of each neighbourhood beyond a voxel (and of the faces-only
// one within), on a random cloud and on a LiDAR-like surface (a noisy
// ground plane with rows of points): the share of the true k nearest
// within max_distance that knn returns
TEST(VoxelMap, RecallOfTheNeighbourhoods) {
  std::mt19937_64 rng(9);
  // a random cloud with its 5th neighbour ~0.3 m away (50 points per m^3)
  const std::vector<Vec3> volume = random_cloud(rng, 16000, {-10.0, -10.0, -2.0}, {10.0, 10.0, 2.0});
  // the ground seen by a spinning LiDAR: rings 0.3 m apart, 2 cm of noise
  std::vector<Vec3> ground;
  std::normal_distribution<double> noise(0.0, 0.02);
  for (double y = -10.0; y < 10.0; y += 0.3)
    for (double x = -10.0; x < 10.0; x += 0.05) ground.push_back(rounded({x, y + noise(rng), noise(rng)}));
  const std::vector<Vec3> volume_queries = random_cloud(rng, 2000, {-9.0, -9.0, -1.5}, {9.0, 9.0, 1.5});
  std::vector<Vec3> ground_queries = random_cloud(rng, 2000, {-9.0, -9.0, -0.05}, {9.0, 9.0, 0.05});

  struct Case {
    const char* scene;
    const std::vector<Vec3>* cloud;
    const std::vector<Vec3>* queries;
    VoxelMapParams::Nearby nearby;
    double max_distance;
    double min_recall;  // asserted (measured: see the printout)
  };
  const Case cases[] = {
      {"volume", &volume, &volume_queries, VoxelMapParams::Nearby6, 0.5, 0.70},
      {"volume", &volume, &volume_queries, VoxelMapParams::Nearby18, 0.5, 0.95},
      {"volume", &volume, &volume_queries, VoxelMapParams::Nearby26, 0.5, 1.0},
      {"volume", &volume, &volume_queries, VoxelMapParams::Nearby26, 1.0, 0.99},
      {"ground", &ground, &ground_queries, VoxelMapParams::Nearby6, 0.5, 0.84},
      {"ground", &ground, &ground_queries, VoxelMapParams::Nearby18, 0.5, 0.985},
      {"ground", &ground, &ground_queries, VoxelMapParams::Nearby26, 0.5, 1.0},
      {"ground", &ground, &ground_queries, VoxelMapParams::Nearby26, 1.0, 0.995},
  };
  std::vector<Neighbour> out;
  for (const Case& c : cases) {
    VoxelMapParams p;
    p.nearby = c.nearby;
    VoxelMap map(p);
    map.insert(*c.cloud);
    const std::vector<Vec3> truth = downsampled(*c.cloud, 0.1);
    long want = 0, hit = 0, exact = 0;
    for (const Vec3& q : *c.queries) {
      const std::vector<Neighbour> t = brute_knn(truth, q, 5, c.max_distance);
      map.knn(q, 5, c.max_distance, out);
      for (const Neighbour& n : t)
        hit += std::any_of(out.begin(), out.end(), [&](const Neighbour& o) { return o.point == n.point; });
      want += static_cast<long>(t.size());
      bool same = out.size() == t.size();
      for (std::size_t i = 0; same && i < t.size(); ++i) same = out[i].point == t[i].point;
      exact += same;
    }
    const double recall = static_cast<double>(hit) / static_cast<double>(want);
    std::printf("recall %-6s %-8s k=5 max_distance %.1f m: %.4f (%ld of %ld), exact answers %.4f\n", c.scene,
                VoxelMapParams::kNearbyNames[c.nearby].name, c.max_distance, recall, hit, want,
                static_cast<double>(exact) / static_cast<double>(c.queries->size()));
    EXPECT_GE(recall, c.min_recall) << c.scene << " " << VoxelMapParams::kNearbyNames[c.nearby].name;
  }
}

TEST(VoxelMap, RemoveOutsideKeepsExactlyThePointsWithinReach) {
  std::mt19937_64 rng(3);
  const std::vector<Vec3> cloud = random_cloud(rng, 30000, {-20.0, -20.0, -2.0}, {20.0, 20.0, 2.0});
  VoxelMap map;
  map.insert(cloud);
  const std::vector<Vec3> all = downsampled(cloud, 0.1);
  const Vec3 centre{3.0, -2.0, 0.5};
  const double reach = 12.3;
  std::vector<Vec3> inside;
  for (const Vec3& p : all)
    if (dist2(p, centre) <= reach * reach) inside.push_back(p);
  ASSERT_GT(inside.size(), 1000u);
  ASSERT_LT(inside.size(), all.size() / 2);

  const std::size_t voxels_before = map.voxels();
  EXPECT_EQ(map.remove_outside(centre, reach), all.size() - inside.size());
  EXPECT_EQ(map.size(), inside.size());
  // nothing beyond the reach remains, everything inside stays
  EXPECT_EQ(sorted(map.points()), inside);
  EXPECT_LT(map.voxels(), voxels_before);
  // and every remaining voxel still holds a point: a box's worth of queries
  // finds exactly what brute force finds in the remaining points
  std::vector<Neighbour> out;
  for (const Vec3& q : random_cloud(rng, 300, {-20.0, -20.0, -2.0}, {20.0, 20.0, 2.0})) {
    map.knn(q, 5, 0.5, out);
    expect_same(out, brute_knn(inside, q, 5, 0.5), "after removal");
  }
  // the freed voxels take new points again
  const std::vector<Vec3> more = random_cloud(rng, 5000, {-20.0, -20.0, -2.0}, {-10.0, -10.0, 2.0});
  map.insert(more);
  std::vector<Vec3> now = inside;  // as inserted: the kept points first, then the new ones
  now.insert(now.end(), more.begin(), more.end());
  const std::vector<Vec3> want = downsampled(now, 0.1);
  EXPECT_EQ(sorted(map.points()), want);
  for (const Vec3& q : random_cloud(rng, 300, {-20.0, -20.0, -2.0}, {-10.0, -10.0, 2.0})) {
    map.knn(q, 5, 0.5, out);
    expect_same(out, brute_knn(want, q, 5, 0.5), "after re-insertion");
  }
  // the params' reach (1000 m) keeps all of it
  EXPECT_EQ(map.remove_outside({0.0, 0.0, 0.0}), 0u);
  EXPECT_EQ(map.size(), want.size());
}

TEST(VoxelMap, TheVoxelCapEvictsTheLeastRecentlyInsertedInto) {
  VoxelMapParams p;
  p.max_voxels = 10;
  VoxelMap map(p);
  // voxel i holds one point at x = 0.5 i + 0.25
  auto point = [](int i) { return Vec3{0.5 * i + 0.25, 0.25, 0.25}; };
  for (int i = 0; i < 15; ++i) map.insert({point(i)});
  EXPECT_EQ(map.voxels(), 10u);
  auto present = [&map, &point](int i) {
    std::vector<Neighbour> out;
    return map.knn(point(i), 1, 0.01, out) == 1;
  };
  for (int i = 0; i < 15; ++i) EXPECT_EQ(present(i), i >= 5) << i;
  // voxel 6 is inserted into again (a skipped point counts too): 5, then 7, go next
  EXPECT_EQ(map.insert({point(6) + Vec3{0.04, 0.0, 0.0}}).skipped, 1);
  const VoxelMap::InsertResult r = map.insert({point(15), point(16)});
  EXPECT_EQ(r.evicted_voxels, 2);
  EXPECT_FALSE(present(5));
  EXPECT_TRUE(present(6));
  EXPECT_FALSE(present(7));
  EXPECT_TRUE(present(16));
  EXPECT_EQ(map.voxels(), 10u);
  EXPECT_EQ(map.size(), 10u);
}

// same inserts and removals in the same order: the same points in the same
// order and the same answers; a map whose hash table and pool have another
// history (other voxels came and went first) gives the same answers too
TEST(VoxelMap, Deterministic) {
  std::mt19937_64 rng(17);
  std::vector<std::vector<Vec3>> scans;
  for (int s = 0; s < 6; ++s)
    scans.push_back(random_cloud(rng, 6000, {-8.0 + 2.0 * s, -6.0, -1.0}, {8.0 + 2.0 * s, 6.0, 1.0}));
  auto build = [&scans](VoxelMap& map) {
    for (int s = 0; s < 6; ++s) {
      map.insert(scans[static_cast<std::size_t>(s)]);
      map.remove_outside({2.0 * s, 0.0, 0.0}, 9.0);
    }
  };
  VoxelMap a, b, c;
  build(a);
  build(b);
  // c: 40000 points elsewhere first (the table grows and rehashes), then gone
  c.insert(random_cloud(rng, 40000, {100.0, 100.0, -5.0}, {140.0, 140.0, 5.0}));
  c.remove_outside({0.0, 0.0, 0.0}, 50.0);
  ASSERT_EQ(c.size(), 0u);
  build(c);
  EXPECT_EQ(a.points(), b.points());
  EXPECT_EQ(sorted(a.points()), sorted(c.points()));
  std::vector<Neighbour> oa, ob, oc;
  for (const Vec3& q : random_cloud(rng, 1000, {-2.0, -6.0, -1.0}, {18.0, 6.0, 1.0})) {
    a.knn(q, 8, 0.5, oa);
    b.knn(q, 8, 0.5, ob);
    c.knn(q, 8, 0.5, oc);
    expect_same(oa, ob, "a, b");
    expect_same(oa, oc, "a, c");
  }
}

TEST(VoxelMap, AQueryAllocatesNothing) {
  std::mt19937_64 rng(23);
  VoxelMap map;
  map.insert(random_cloud(rng, 20000, {-5.0, -5.0, -1.0}, {5.0, 5.0, 1.0}));
  const std::vector<Vec3> queries = random_cloud(rng, 1000, {-5.0, -5.0, -1.0}, {5.0, 5.0, 1.0});
  std::vector<Neighbour> out;
  out.reserve(5);
  int found = 0;
  const long before = g_allocations.load();
  for (const Vec3& q : queries) found += map.knn(q, 5, 1.0, out);
  EXPECT_EQ(g_allocations.load(), before);
  EXPECT_GT(found, 4000);
}

TEST(VoxelMap, BadInputIsIgnoredAndCounted) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  VoxelMap map;
  std::vector<Neighbour> out{{Vec3::Zero(), 0.0}};
  // an empty map answers nothing
  EXPECT_EQ(map.knn({0.0, 0.0, 0.0}, 5, 1.0, out), 0);
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(map.remove_outside({0.0, 0.0, 0.0}, 1.0), 0u);
  EXPECT_EQ(map.insert({}).added, 0);

  const VoxelMap::InsertResult r =
      map.insert({{nan, 0.0, 0.0}, {0.0, inf, 0.0}, {0.0, 0.0, -inf}, {1e300, 0.0, 0.0}, {2e8, 0.0, 0.0}, {1.0, 1.0, 1.0}});
  EXPECT_EQ(r.rejected, 5);
  EXPECT_EQ(r.added, 1);
  EXPECT_EQ(map.rejected(), 5u);
  EXPECT_EQ(map.size(), 1u);

  EXPECT_EQ(map.knn({1.0, 1.0, 1.0}, 0, 1.0, out), 0);
  EXPECT_EQ(map.knn({1.0, 1.0, 1.0}, -3, 1.0, out), 0);
  EXPECT_EQ(map.knn({nan, 1.0, 1.0}, 5, 1.0, out), 0);
  EXPECT_EQ(map.knn({1.0, 1.0, inf}, 5, 1.0, out), 0);
  EXPECT_EQ(map.knn({1e300, 1.0, 1.0}, 5, 1.0, out), 0);
  EXPECT_EQ(map.knn({1.0, 1.0, 1.0}, 5, nan, out), 0);
  EXPECT_EQ(map.knn({1.0, 1.0, 1.0}, 5, -1.0, out), 0);
  EXPECT_TRUE(out.empty());
  // no limit but the neighbourhood; a point at the query is at distance 0
  EXPECT_EQ(map.knn({1.2, 1.0, 1.0}, 5, inf, out), 1);
  EXPECT_EQ(map.knn({1.0, 1.0, 1.0}, 5, 0.0, out), 1);

  EXPECT_EQ(map.remove_outside({nan, 0.0, 0.0}, 1.0), 0u);
  EXPECT_EQ(map.remove_outside({0.0, 0.0, 0.0}, nan), 0u);
  EXPECT_EQ(map.remove_outside({0.0, 0.0, 0.0}, -1.0), 0u);
  EXPECT_EQ(map.remove_outside({0.0, 0.0, 0.0}, inf), 0u);
  EXPECT_EQ(map.size(), 1u);
  EXPECT_EQ(map.remove_outside({0.0, 0.0, 0.0}, 0.0), 1u);
  EXPECT_EQ(map.size(), 0u);
  EXPECT_EQ(map.voxels(), 0u);

  map.insert({{1.0, 1.0, 1.0}});
  map.clear();
  EXPECT_EQ(map.size(), 0u);
  EXPECT_EQ(map.rejected(), 0u);
  EXPECT_EQ(map.knn({1.0, 1.0, 1.0}, 5, 1.0, out), 0);
}

TEST(VoxelMap, ParamsAreValidated) {
  EXPECT_EQ(params::validate(VoxelMapParams{}), "");
  VoxelMapParams p;
  p.voxel_size = 0.55;  // not a whole number of 0.1 m leaves
  EXPECT_NE(params::validate(p), "");
  EXPECT_THROW(VoxelMap{p}, std::invalid_argument);
  p.voxel_size = 0.1;  // one leaf a voxel is fine
  EXPECT_EQ(params::validate(p), "");
  p.leaf_size = 0.2;
  EXPECT_NE(params::validate(p), "");
  p = {};
  p.reach = 0.0;
  EXPECT_THROW(VoxelMap{p}, std::invalid_argument);
  p = {};
  p.max_voxels = 0;
  EXPECT_THROW(VoxelMap{p}, std::invalid_argument);
  p = {};
  p.nearby = static_cast<VoxelMapParams::Nearby>(3);
  EXPECT_NE(params::validate(p), "");
}

}  // namespace
}  // namespace paddock::slam
