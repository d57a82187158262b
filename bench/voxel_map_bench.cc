// the LiDAR-inertial odometry's map (autonomy/slam/voxel_map.h) against
// nanoflann on the same data in the same run: the car drives the bench
// oval (bench_scenes.h: ~305 m, 200 cones) at 1 m per scan past barriers
// and two buildings, and each scan is used as the odometry uses it: its
// 0.5 m down-sampling (FAST-LIO2's scan filter, ~2-4k points) asks for the
// k = 5 nearest map points of each of its points, then the whole scan goes
// into the map and what lies beyond the map's reach (60 m) leaves it.
//
// The scan: a ray cast of the project's LiDAR layout (hal::LidarLayout: 32
// rings over -8 .. +7.5 deg, 1024 columns, 0.15 m above the ground; 0.5 -
// 50 m, 2 cm range noise) against flat ground, the cones (the simulator's
// small cone: a truncated cone of 0.228 m base, 0.325 m high) and vertical
// walls (1 m and 0.8 m barriers along half the lap, two 4 m buildings).
// The first 20 scans build the map untimed; each benchmark then times the
// same 150 scans (150 m of the lap). The order of each scan's work is the
// odometry's: a scan is made (and down-sampled) before its queries, so the
// voxel map meets them as the odometry would leave it; a static tree is
// built just before its queries, as a rebuild per scan would be.
//
//   BM_VoxelMapInsert          insert() of one scan and remove_outside()
//   BM_VoxelMapKnn             knn for one scan's queries (nearby, max_distance in cm);
//                              recall: against exact neighbours, every 10th scan
//   BM_KdTreeBuild             nanoflann KDTreeSingleIndexAdaptor over the
//                              voxel map's points (rebuilt per scan)
//   BM_KdTreeKnn               its k nearest within max_distance, same queries
//   BM_KdTreeDynamicUpdate     KDTreeSingleIndexDynamicAdaptor: addPoints of
//                              the points the voxel map took in, removePoint of
//                              those it dropped (the down-sampling decisions
//                              are the voxel map's, not timed here)
//   BM_KdTreeDynamicKnn        its k nearest within max_distance
//
// Run: ./build/paddock_bench --benchmark_filter='VoxelMap|KdTree'
#include <benchmark/benchmark.h>

#include <nanoflann.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <random>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

#include "autonomy/common/geometry.h"
#include "autonomy/hal/lidar_layout.h"
#include "autonomy/slam/voxel_map.h"
#include "bench/bench_scenes.h"

namespace {

using namespace paddock;
using Vec3 = Eigen::Vector3d;

constexpr double kRangeMin = 0.5;
constexpr double kRangeMax = 50.0;
constexpr double kRangeNoise = 0.02;
constexpr double kStep = 1.0;      // m driven per scan
constexpr double kQueryLeaf = 0.5;  // the scan's down-sampling for the queries
constexpr int kWarmup = 20;
constexpr int kScans = 150;
constexpr int kK = 5;

// the simulator's small cone (sim/sensors/lidar.h)
constexpr double kConeBase = 0.114, kConeTop = 0.03, kConeHeight = 0.325;

struct Wall {
  Vec2 a, b;
  double height;
};

// the oval, its cones and walls, and a ray-cast LiDAR
class Scene {
 public:
  Scene() : cones_(), layout_() {
    for (const Cone& c : bench::oval_cones(100)) cones_.push_back(c.position);
    // arc length -> t, every 0.01 m
    double s = 0.0;
    Vec2 prev = bench::oval_centreline(0.0);
    arc_.push_back(0.0);
    for (double t = 1e-5; t < 2.0 * kPi; t += 1e-5) {
      const Vec2 p = bench::oval_centreline(t);
      s += distance(p, prev);
      prev = p;
      while (static_cast<double>(arc_.size()) * 0.01 <= s) arc_.push_back(t);
    }
    // barriers along the oval (outwards is to the right of the
    // counter-clockwise centreline): 1 m high 9 m out on t in [0.3, 2.8],
    // 0.8 m high 8 m in on t in [3.5, 5.5]
    auto barrier = [this](double t0, double t1, double offset, double height) {
      for (double t = t0; t < t1; t += 0.02) {
        const auto at = [offset](double u) {
          return bench::oval_centreline(u) + offset * left_normal(bench::oval_tangent(u));
        };
        walls_.push_back({at(t), at(t + 0.02), height});
      }
    };
    barrier(0.3, 2.8, -9.0, 1.0);
    barrier(3.5, 5.5, 8.0, 0.8);
    // two buildings, 20 m x 10 m, 4 m high, 25 m outside the oval
    for (const double t : {1.2, 4.2}) {
      const Vec2 along = bench::oval_tangent(t);
      const Vec2 out = -1.0 * left_normal(along);
      const Vec2 c = bench::oval_centreline(t) + 25.0 * out;
      const Vec2 corners[4] = {c - 10.0 * along - 5.0 * out, c + 10.0 * along - 5.0 * out,
                               c + 10.0 * along + 5.0 * out, c - 10.0 * along + 5.0 * out};
      for (int i = 0; i < 4; ++i) walls_.push_back({corners[i], corners[(i + 1) % 4], 4.0});
    }
    bins_.resize(static_cast<std::size_t>(layout_.columns));
  }

  // the sensor at arc length s (m) along the centreline, looking along it
  Pose2 pose(double s) const {
    const std::size_t i = static_cast<std::size_t>(std::lround(s / 0.01)) % arc_.size();
    const double t = arc_[i];
    const Vec2 p = bench::oval_centreline(t);
    return {p.x, p.y, angle_of(bench::oval_tangent(t))};
  }

  // one rotation from pose (no motion during it: the odometry deskews), world frame
  void scan(const Pose2& pose, std::mt19937_64& rng, std::vector<Vec3>& out) {
    out.clear();
    const Vec3 o(pose.x, pose.y, layout_.mount_z);
    const int columns = layout_.columns;
    const double per_column = 2.0 * kPi / columns;
    // column c looks at azimuth yaw - pi + 2 pi c / columns
    auto column_of = [&](double azimuth) {
      return static_cast<int>(std::floor((wrap_angle(azimuth - pose.yaw) + kPi) / per_column));
    };
    auto add_span = [&](double a0, double width, int id) {
      const int c0 = column_of(a0) - 1;
      const int n = static_cast<int>(std::ceil(width / per_column)) + 3;
      for (int c = c0; c < c0 + n; ++c) bins_[static_cast<std::size_t>(((c % columns) + columns) % columns)].push_back(id);
    };
    for (auto& b : bins_) b.clear();
    for (std::size_t i = 0; i < cones_.size(); ++i) {
      const Vec2 d = cones_[i] - pose.position();
      const double r = norm(d);
      if (r > kRangeMax + 1.0 || r < kConeBase) continue;
      const double half = std::asin(std::min(1.0, kConeBase / r));
      add_span(angle_of(d) - half, 2.0 * half, static_cast<int>(i));
    }
    for (std::size_t j = 0; j < walls_.size(); ++j) {
      const Wall& w = walls_[j];
      if (std::min(distance(w.a, pose.position()), distance(w.b, pose.position())) > kRangeMax + 30.0) continue;
      const double a = angle_of(w.a - pose.position());
      const double span = wrap_angle(angle_of(w.b - pose.position()) - a);
      add_span(span >= 0.0 ? a : a + span, std::abs(span), -1 - static_cast<int>(j));
    }

    std::normal_distribution<double> noise(0.0, kRangeNoise);
    for (int c = 0; c < columns; ++c) {
      const double azimuth = pose.yaw - kPi + c * per_column;
      const double ca = std::cos(azimuth), sa = std::sin(azimuth);
      for (int ch = 0; ch < layout_.channels; ++ch) {
        const double e = layout_.elevation_min +
                         (layout_.elevation_max - layout_.elevation_min) * ch / (layout_.channels - 1);
        const Vec3 d(std::cos(e) * ca, std::cos(e) * sa, std::sin(e));
        double t = d.z() < 0.0 ? -o.z() / d.z() : kRangeMax + 1.0;
        for (const int id : bins_[static_cast<std::size_t>(c)])
          t = std::min(t, id >= 0 ? hit_cone(cones_[static_cast<std::size_t>(id)], o, d)
                                  : hit_wall(walls_[static_cast<std::size_t>(-1 - id)], o, d));
        if (t < kRangeMin || t > kRangeMax) continue;
        out.push_back(o + (t + noise(rng)) * d);
      }
    }
  }

 private:
  // ray o + t d against a cone standing at c: (x - cx)^2 + (y - cy)^2 =
  // (base - k z)^2, k = (base - top) / height, 0 <= z <= height
  static double hit_cone(const Vec2& c, const Vec3& o, const Vec3& d) {
    const double k = (kConeBase - kConeTop) / kConeHeight;
    const double dx = o.x() - c.x, dy = o.y() - c.y;
    const double r0 = kConeBase - k * o.z();
    const double a = d.x() * d.x() + d.y() * d.y() - k * k * d.z() * d.z();
    const double b = 2.0 * (dx * d.x() + dy * d.y()) + 2.0 * k * d.z() * r0;
    const double cc = dx * dx + dy * dy - r0 * r0;
    const double disc = b * b - 4.0 * a * cc;
    if (disc < 0.0 || a == 0.0) return kInfinity;
    const double sq = std::sqrt(disc);
    double t0 = (-b - sq) / (2.0 * a), t1 = (-b + sq) / (2.0 * a);
    if (t0 > t1) std::swap(t0, t1);
    for (const double t : {t0, t1}) {
      const double z = o.z() + t * d.z();
      if (t > 0.0 && z >= 0.0 && z <= kConeHeight) return t;
    }
    return kInfinity;
  }
  // ray against a vertical wall from a to b, 0 <= z <= height
  static double hit_wall(const Wall& w, const Vec3& o, const Vec3& d) {
    const Vec2 dir{d.x(), d.y()}, ab = w.b - w.a, ao = w.a - Vec2{o.x(), o.y()};
    const double den = cross(dir, ab);
    if (std::abs(den) < 1e-12) return kInfinity;
    const double t = cross(ao, ab) / den, u = cross(ao, dir) / den;
    const double z = o.z() + t * d.z();
    return t > 0.0 && u >= 0.0 && u <= 1.0 && z >= 0.0 && z <= w.height ? t : kInfinity;
  }
  static constexpr double kInfinity = 1e300;

  std::vector<Vec2> cones_;
  std::vector<Wall> walls_;
  std::vector<double> arc_;  // t at every 0.01 m of arc length
  hal::LidarLayout layout_;
  std::vector<std::vector<int>> bins_;  // per column: cones (>= 0) and walls (-1 - index) it may meet
};

// the centroids of the points in each kQueryLeaf cell (a PCL voxel grid, as
// FAST-LIO2 filters each scan before matching), in cell order
void downsample(const std::vector<Vec3>& scan, std::vector<Vec3>& out) {
  std::map<std::array<std::int64_t, 3>, std::pair<Vec3, int>> cells;
  for (const Vec3& p : scan) {
    const std::array<std::int64_t, 3> key = {static_cast<std::int64_t>(std::floor(p.x() / kQueryLeaf)),
                                             static_cast<std::int64_t>(std::floor(p.y() / kQueryLeaf)),
                                             static_cast<std::int64_t>(std::floor(p.z() / kQueryLeaf))};
    // (an Eigen vector is not zeroed by default construction: no operator[])
    auto& cell = cells.try_emplace(key, Vec3::Zero(), 0).first->second;
    cell.first += p;
    ++cell.second;
  }
  out.clear();
  for (const auto& [key, cell] : cells) out.push_back(cell.first / static_cast<double>(cell.second));
}

// the drive: one scan and its queries per step, 1 m apart
struct Drive {
  Scene scene;
  std::mt19937_64 rng{1};
  double s = 0.0;
  Vec3 sensor = Vec3::Zero();
  std::vector<Vec3> scan, queries;
  void next() {
    const Pose2 p = scene.pose(s);
    sensor = {p.x, p.y, hal::LidarLayout{}.mount_z};
    scene.scan(p, rng, scan);
    downsample(scan, queries);
    s += kStep;
  }
};

// the map's parameters with a 60 m reach: this drive's figures are a map
// that trims what lies beyond the LiDAR's range (the LIO's default keeps
// 1000 m: a whole track)
slam::VoxelMapParams sixty() {
  slam::VoxelMapParams p;
  p.reach = 60.0;
  return p;
}

// the map as the odometry keeps it: query, then insert, then trim
struct MapDrive {
  Drive drive;
  slam::VoxelMap map;
  long scan_points = 0, query_points = 0, added = 0, full = 0, scans = 0;

  explicit MapDrive(const slam::VoxelMapParams& p = sixty()) : map(p) {
    for (int i = 0; i < kWarmup; ++i) {
      drive.next();
      update();
    }
    scan_points = query_points = added = full = scans = 0;
  }
  void update() {
    const slam::VoxelMap::InsertResult r = map.insert(drive.scan);
    map.remove_outside(drive.sensor);
    scan_points += static_cast<long>(drive.scan.size());
    query_points += static_cast<long>(drive.queries.size());
    added += r.added;
    full += r.full;
    ++scans;
  }
  void report(benchmark::State& state) const {
    const double n = static_cast<double>(std::max<long>(scans, 1));
    state.counters["scan_pts"] = static_cast<double>(scan_points) / n;
    state.counters["queries"] = static_cast<double>(query_points) / n;
    state.counters["map_pts"] = static_cast<double>(map.size());
    state.counters["voxels"] = static_cast<double>(map.voxels());
    state.counters["added"] = static_cast<double>(added) / n;
    state.counters["full"] = static_cast<double>(full) / n;
  }
};

// nanoflann's view of a float point list
struct Cloud {
  std::vector<std::array<float, 3>> pts;
  std::size_t kdtree_get_point_count() const { return pts.size(); }
  float kdtree_get_pt(std::size_t i, std::size_t dim) const { return pts[i][dim]; }
  template <class B>
  bool kdtree_get_bbox(B&) const { return false; }
};
using Metric = nanoflann::L2_Simple_Adaptor<float, Cloud, float, std::uint32_t>;
using StaticTree = nanoflann::KDTreeSingleIndexAdaptor<Metric, Cloud, 3, std::uint32_t>;
using DynamicTree = nanoflann::KDTreeSingleIndexDynamicAdaptor<Metric, Cloud, 3, std::uint32_t>;

void export_points(const slam::VoxelMap& map, Cloud& cloud) {
  cloud.pts.clear();
  for (const Vec3& p : map.points())
    cloud.pts.push_back({static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())});
}

// the k nearest within max_distance: a result set whose worst distance
// starts at max_distance^2 (nanoflann prunes with it from the start)
template <class Tree>
int tree_knn(const Tree& tree, const Vec3& q, double max_distance, std::uint32_t* idx, float* d2) {
  nanoflann::KNNResultSet<float, std::uint32_t> rs(kK);
  rs.init(idx, d2);
  d2[kK - 1] = static_cast<float>(max_distance * max_distance);
  const float p[3] = {static_cast<float>(q.x()), static_cast<float>(q.y()), static_cast<float>(q.z())};
  tree.findNeighbors(rs, p, nanoflann::SearchParams());
  return static_cast<int>(rs.size());
}

// the share of the exact k nearest within max_distance (by the map's own
// metric and order, from a radius search of an exact KD-tree) that knn finds
struct Recall {
  long want = 0, hit = 0;
  void add(const slam::VoxelMap& map, const std::vector<Vec3>& queries, double max_distance) {
    Cloud cloud;
    export_points(map, cloud);
    StaticTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
    std::vector<std::pair<std::uint32_t, float>> found;
    std::vector<slam::VoxelMap::Neighbour> truth, got;
    for (const Vec3& q : queries) {
      const float p[3] = {static_cast<float>(q.x()), static_cast<float>(q.y()), static_cast<float>(q.z())};
      const float r = static_cast<float>(max_distance + 0.01);
      tree.radiusSearch(p, r * r, found, nanoflann::SearchParams(32, 0.0f, false));
      truth.clear();
      for (const auto& [i, unused] : found) {
        const Vec3 m(cloud.pts[i][0], cloud.pts[i][1], cloud.pts[i][2]);
        const double dx = m.x() - q.x(), dy = m.y() - q.y(), dz = m.z() - q.z();
        const double d2 = (dx * dx + dy * dy) + dz * dz;
        if (d2 <= max_distance * max_distance) truth.push_back({m, d2});
      }
      std::sort(truth.begin(), truth.end(), [](const auto& a, const auto& b) {
        if (a.distance2 != b.distance2) return a.distance2 < b.distance2;
        return std::lexicographical_compare(a.point.data(), a.point.data() + 3, b.point.data(), b.point.data() + 3);
      });
      if (truth.size() > static_cast<std::size_t>(kK)) truth.resize(kK);
      map.knn(q, kK, max_distance, got);
      for (const auto& t : truth)
        hit += std::any_of(got.begin(), got.end(), [&t](const auto& g) { return g.point == t.point; });
      want += static_cast<long>(truth.size());
    }
  }
  double value() const { return want > 0 ? static_cast<double>(hit) / static_cast<double>(want) : 1.0; }
};

void BM_VoxelMapInsert(benchmark::State& state) {
  MapDrive m;
  for (auto _ : state) {
    state.PauseTiming();
    m.drive.next();
    state.ResumeTiming();
    m.update();
  }
  m.report(state);
  state.counters["points/s"] =
      benchmark::Counter(static_cast<double>(m.scan_points), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_VoxelMapInsert)->Iterations(kScans)->Unit(benchmark::kMillisecond);

void BM_VoxelMapKnn(benchmark::State& state) {
  slam::VoxelMapParams p = sixty();
  p.nearby = state.range(0) == 6 ? slam::VoxelMapParams::Nearby6
             : state.range(0) == 18 ? slam::VoxelMapParams::Nearby18
                                    : slam::VoxelMapParams::Nearby26;
  const double max_distance = static_cast<double>(state.range(1)) / 100.0;
  MapDrive m(p);
  Recall recall;
  std::vector<slam::VoxelMap::Neighbour> out;
  out.reserve(kK);
  long found = 0;
  for (auto _ : state) {
    state.PauseTiming();
    m.drive.next();
    if (m.scans % 10 == 0) recall.add(m.map, m.drive.queries, max_distance);
    state.ResumeTiming();
    for (const Vec3& q : m.drive.queries) found += m.map.knn(q, kK, max_distance, out);
    state.PauseTiming();
    m.update();
    state.ResumeTiming();
  }
  m.report(state);
  state.counters["queries/s"] =
      benchmark::Counter(static_cast<double>(m.query_points), benchmark::Counter::kIsRate);
  state.counters["found"] = static_cast<double>(found) / static_cast<double>(std::max<long>(m.query_points, 1));
  state.counters["recall"] = recall.value();
}
BENCHMARK(BM_VoxelMapKnn)
    ->ArgNames({"nearby", "max_cm"})
    ->Args({26, 50})
    ->Args({26, 100})
    ->Args({18, 50})
    ->Args({6, 50})
    ->Iterations(kScans)
    ->Unit(benchmark::kMillisecond);

void BM_KdTreeBuild(benchmark::State& state) {
  MapDrive m;
  Cloud cloud;
  for (auto _ : state) {
    state.PauseTiming();
    m.drive.next();
    export_points(m.map, cloud);
    state.ResumeTiming();
    StaticTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
    benchmark::DoNotOptimize(&tree);
    state.PauseTiming();
    m.update();
    state.ResumeTiming();
  }
  m.report(state);
}
BENCHMARK(BM_KdTreeBuild)->Iterations(kScans)->Unit(benchmark::kMillisecond);

void BM_KdTreeKnn(benchmark::State& state) {
  const double max_distance = static_cast<double>(state.range(0)) / 100.0;
  MapDrive m;
  Cloud cloud;
  std::uint32_t idx[kK];
  float d2[kK];
  long found = 0;
  for (auto _ : state) {
    state.PauseTiming();
    m.drive.next();
    export_points(m.map, cloud);
    StaticTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
    state.ResumeTiming();
    for (const Vec3& q : m.drive.queries) found += tree_knn(tree, q, max_distance, idx, d2);
    state.PauseTiming();
    m.update();
    state.ResumeTiming();
  }
  m.report(state);
  state.counters["queries/s"] =
      benchmark::Counter(static_cast<double>(m.query_points), benchmark::Counter::kIsRate);
  state.counters["found"] = static_cast<double>(found) / static_cast<double>(std::max<long>(m.query_points, 1));
}
BENCHMARK(BM_KdTreeKnn)->ArgName("max_cm")->Arg(50)->Arg(100)->Iterations(kScans)->Unit(benchmark::kMillisecond);

// nanoflann's dynamic index fed what the voxel map decided: every point
// the map holds and the index does not is added, every point the index
// holds and the map does not is removed (the index keeps all points ever
// added in its dataset; removal only marks them)
struct DynamicDrive {
  struct Key {
    std::uint32_t x, y, z;
    bool operator==(const Key& o) const { return x == o.x && y == o.y && z == o.z; }
  };
  struct KeyHash {
    std::size_t operator()(const Key& k) const {
      return (static_cast<std::size_t>(k.x) * 73856093u) ^ (static_cast<std::size_t>(k.y) * 19349663u) ^
             (static_cast<std::size_t>(k.z) * 83492791u);
    }
  };
  static Key key_of(const std::array<float, 3>& p) {
    Key k;
    std::memcpy(&k.x, &p[0], 4);
    std::memcpy(&k.y, &p[1], 4);
    std::memcpy(&k.z, &p[2], 4);
    return k;
  }

  MapDrive m;
  Cloud dataset;  // every point ever added
  DynamicTree tree{3, dataset, nanoflann::KDTreeSingleIndexAdaptorParams(10), 1u << 24};
  std::unordered_map<Key, std::uint32_t, KeyHash> live;  // point -> dataset index
  std::vector<std::uint32_t> gone;
  std::size_t first_new = 0;

  DynamicDrive() { plan(); apply(); }
  // what changes (untimed)
  void plan() {
    Cloud now;
    export_points(m.map, now);
    std::unordered_map<Key, std::uint32_t, KeyHash> next;
    first_new = dataset.pts.size();
    for (const auto& p : now.pts) {
      const Key k = key_of(p);
      const auto it = live.find(k);
      if (it != live.end()) {
        next.emplace(k, it->second);
      } else {
        next.emplace(k, static_cast<std::uint32_t>(dataset.pts.size()));
        dataset.pts.push_back(p);
      }
    }
    gone.clear();
    for (const auto& [k, i] : live)
      if (next.find(k) == next.end()) gone.push_back(i);
    std::sort(gone.begin(), gone.end());
    live.swap(next);
  }
  // the index's own work (timed)
  void apply() {
    if (dataset.pts.size() > first_new)
      tree.addPoints(static_cast<std::uint32_t>(first_new), static_cast<std::uint32_t>(dataset.pts.size() - 1));
    for (const std::uint32_t i : gone) tree.removePoint(i);
  }
};

void BM_KdTreeDynamicUpdate(benchmark::State& state) {
  DynamicDrive d;
  for (auto _ : state) {
    state.PauseTiming();
    d.m.drive.next();
    d.m.update();
    d.plan();
    state.ResumeTiming();
    d.apply();
  }
  d.m.report(state);
  state.counters["dataset"] = static_cast<double>(d.dataset.pts.size());
}
BENCHMARK(BM_KdTreeDynamicUpdate)->Iterations(kScans)->Unit(benchmark::kMillisecond);

void BM_KdTreeDynamicKnn(benchmark::State& state) {
  const double max_distance = static_cast<double>(state.range(0)) / 100.0;
  DynamicDrive d;
  std::uint32_t idx[kK];
  float d2[kK];
  long found = 0;
  for (auto _ : state) {
    state.PauseTiming();
    d.m.drive.next();
    state.ResumeTiming();
    for (const Vec3& q : d.m.drive.queries) found += tree_knn(d.tree, q, max_distance, idx, d2);
    state.PauseTiming();
    d.m.update();
    d.plan();
    d.apply();
    state.ResumeTiming();
  }
  d.m.report(state);
  state.counters["queries/s"] =
      benchmark::Counter(static_cast<double>(d.m.query_points), benchmark::Counter::kIsRate);
  state.counters["found"] = static_cast<double>(found) / static_cast<double>(std::max<long>(d.m.query_points, 1));
  state.counters["dataset"] = static_cast<double>(d.dataset.pts.size());
}
BENCHMARK(BM_KdTreeDynamicKnn)->ArgName("max_cm")->Arg(50)->Iterations(kScans)->Unit(benchmark::kMillisecond);

}  // namespace
