// the LiDAR pipeline (motion correction, ground removal, clustering, cone
// reconstruction and filters, intensity colour) on scans of the simulator's
// ray-cast LiDAR, checked against the simulator's ground truth: every return
// carries the index of the cone it hit (-1: ground), and the cones' true
// positions are known.
#include "autonomy/perception/lidar_pipeline.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "sim/sensors/lidar.h"
#include "sim/world/track.h"
#include "sim/world/venue.h"

namespace paddock::perception {
namespace {

// the calibration the stack is told: the simulated sensor's own numbers
LidarCalibration calibration_of(const sensors::LidarParams& p) {
  LidarCalibration c;
  c.mount_x = p.mount_x;
  c.mount_y = p.mount_y;
  c.mount_z = p.mount_z;
  c.mount_pitch = p.mount_pitch;
  c.channels = p.channels;
  c.elevation_min = p.elevation_min;
  c.elevation_max = p.elevation_max;
  c.columns = p.columns;
  return c;
}

LidarPipelineParams pipeline_params(const sensors::LidarParams& p) {
  LidarPipelineParams pp;
  pp.calibration = calibration_of(p);
  return pp;
}

// a scan as the HAL delivers it, and the truth kept on the side
struct TruthScan {
  hal::LidarScan scan;
  std::vector<std::int32_t> cone;  // per point: cone index, -1 ground
};

TruthScan make_scan(sensors::Lidar& lidar, const sensors::LidarWorld& world,
                    const std::function<Pose2(TimeNs)>& pose_at, TimeNs start) {
  TruthScan out;
  const std::vector<sensors::LidarPoint> pts = lidar.scan(world, pose_at, start);
  out.scan.stamp = start;
  out.scan.end = lidar.column_time(start, lidar.params().columns - 1);
  out.scan.points.reserve(pts.size());
  for (const sensors::LidarPoint& q : pts) {
    out.scan.points.push_back({q.x, q.y, q.z, q.intensity, q.ring, q.t});
    out.cone.push_back(q.cone);
  }
  return out;
}

std::function<Pose2(TimeNs)> at_rest(Pose2 pose) {
  return [pose](TimeNs) { return pose; };
}

// a cone's true position in the base frame at time t
Vec2 in_base(const Pose2& base, Vec2 world) { return base.inverse_transform(world); }

// detections matched to the truth: each truth cone to its nearest detection
// within `gate`, each detection used once (greedy by distance)
struct Match {
  int true_positives = 0, truths = 0, detections = 0;
  double error_sum = 0.0, error_max = 0.0;
  std::vector<int> detection_of;  // per truth cone, -1 none
  double precision() const { return detections == 0 ? 1.0 : double(true_positives) / detections; }
  double recall() const { return truths == 0 ? 1.0 : double(true_positives) / truths; }
  double mean_error() const { return true_positives == 0 ? 0.0 : error_sum / true_positives; }
};

Match match(const std::vector<Vec2>& truth, const std::vector<Vec2>& det, double gate) {
  Match m;
  m.truths = static_cast<int>(truth.size());
  m.detections = static_cast<int>(det.size());
  m.detection_of.assign(truth.size(), -1);
  struct Pair {
    double d;
    std::size_t t, k;
  };
  std::vector<Pair> pairs;
  for (std::size_t t = 0; t < truth.size(); ++t) {
    for (std::size_t k = 0; k < det.size(); ++k) {
      const double d = distance(truth[t], det[k]);
      if (d <= gate) pairs.push_back({d, t, k});
    }
  }
  std::sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) { return a.d < b.d; });
  std::vector<bool> used(det.size(), false);
  for (const Pair& p : pairs) {
    if (m.detection_of[p.t] >= 0 || used[p.k]) continue;
    m.detection_of[p.t] = static_cast<int>(p.k);
    used[p.k] = true;
    ++m.true_positives;
    m.error_sum += p.d;
    m.error_max = std::max(m.error_max, p.d);
  }
  return m;
}

std::vector<Vec2> xy_of(const std::vector<ConeCandidate>& cones) {
  std::vector<Vec2> out;
  for (const ConeCandidate& c : cones) out.push_back({c.centre.x(), c.centre.y()});
  return out;
}

// ------------------------------------------------------------- motion

// 10 m/s with a 1 rad/s yaw rate: over the 0.1 s rotation the car turns
// 0.1 rad and moves 1 m; cones seen early in the rotation (behind the car)
// are displaced most
TEST(LidarPipelineTest, MotionCorrectionRemovesTheTurnsDistortion) {
  const double v = 10.0, w = 1.0;
  const auto pose_at = [v, w](TimeNs t) {
    const double s = to_seconds(t);
    return Pose2{v / w * std::sin(w * s), v / w * (1.0 - std::cos(w * s)), w * s};
  };
  sensors::LidarParams lp;  // default noise
  sensors::Lidar lidar(lp, 11);
  const TimeNs start = from_seconds(1.0);
  const TimeNs end = lidar.column_time(start, lp.columns - 1);
  // cones placed around the car as it stands at the scan's end
  const Pose2 base_end = pose_at(end);
  const std::vector<Vec2> in_end = {{8.0, 2.0},  {10.0, -3.0}, {4.0, 5.0}, {5.0, -5.0}, {-4.0, 4.0},
                                    {-6.0, -3.0}, {-8.0, 0.5}, {1.0, 7.0}, {2.5, -7.0}, {12.0, 0.0}};
  std::vector<Cone> cones;
  for (Vec2 p : in_end) cones.push_back({base_end.transform(p), ConeColor::Blue});
  sensors::LidarWorld world(cones);
  const TruthScan ts = make_scan(lidar, world, pose_at, start);

  // exact odometry messages of the motion
  Odometry odo;
  const double r = odo.params().wheel_radius;
  for (TimeNs t = start - from_seconds(0.5); t <= end + from_seconds(0.05); t += 5'000'000) {
    odo.add(hal::Imu{t, 0.0, v * w, w});
    odo.add(hal::WheelSpeeds{t, {v / r, v / r, (v - 0.6 * w) / r, (v + 0.6 * w) / r}});
  }

  LidarPipeline pipeline(pipeline_params(lp));
  const LidarResult corrected = pipeline.process(ts.scan, &odo);
  const LidarResult raw = pipeline.process(ts.scan, nullptr);
  ASSERT_TRUE(corrected.ok) << corrected.status;
  ASSERT_TRUE(raw.ok) << raw.status;
  EXPECT_TRUE(corrected.corrected);
  EXPECT_FALSE(raw.corrected);
  EXPECT_NE(raw.status.find("no odometry"), std::string::npos) << raw.status;

  const Match mc = match(in_end, xy_of(corrected.cones), 2.0);
  const Match mr = match(in_end, xy_of(raw.cones), 2.0);
  std::printf("turning 10 m/s, 1 rad/s: corrected mean error %.3f m (max %.3f, %d/%d matched), "
              "uncorrected mean %.3f m (max %.3f, %d/%d)\n",
              mc.mean_error(), mc.error_max, mc.true_positives, mc.truths, mr.mean_error(), mr.error_max,
              mr.true_positives, mr.truths);
  // measured: corrected mean 0.011 m (max 0.029), uncorrected mean 0.60 m (max 1.33)
  EXPECT_EQ(mc.true_positives, mc.truths);
  EXPECT_LT(mc.mean_error(), 0.05);
  EXPECT_LT(mc.error_max, 0.08);
  EXPECT_GT(mr.mean_error(), 0.3);
  EXPECT_GT(mr.mean_error(), 8.0 * mc.mean_error());
}

// ------------------------------------------------------------- ground

// cones on rings of 3 .. 18 m around a car at rest
std::vector<Cone> cone_rings(const Pose2& base, double sensor_x, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  std::vector<Cone> cones;
  const double radii[] = {3.0, 5.0, 7.0, 9.5, 12.0, 15.0, 18.0};
  for (std::size_t k = 0; k < std::size(radii); ++k) {
    const int n = 8 + 2 * static_cast<int>(k);
    for (int i = 0; i < n; ++i) {
      const double a = 2.0 * kPi * (i + 0.5 * static_cast<double>(k % 2)) / n + jitter(rng);
      const Vec2 local{sensor_x + radii[k] * std::cos(a), radii[k] * std::sin(a)};
      cones.push_back({base.transform(local), i % 2 == 0 ? ConeColor::Blue : ConeColor::Yellow});
    }
  }
  return cones;
}

struct GroundCase {
  const char* name;
  double slope_x, slope_y, bump;
  // the bounds asserted, a little below the measured values (see the table
  // at INSTANTIATE_TEST_SUITE_P)
  double min_ground, min_kept, min_in_cones;
};

class LidarGround : public ::testing::TestWithParam<GroundCase> {};

TEST_P(LidarGround, GroundIsRemovedAndConesAreKept) {
  const GroundCase gc = GetParam();
  sensors::GroundParams g;
  g.slope_x = gc.slope_x;
  g.slope_y = gc.slope_y;
  g.bump_height = gc.bump;
  g.bump_wavelength = 10.0;
  sensors::LidarParams lp;
  const Pose2 base{3.0, -2.0, 0.4};
  const std::vector<Cone> cones = cone_rings(base, lp.mount_x, 5);
  sensors::LidarWorld world(cones, {}, g);
  sensors::Lidar lidar(lp, 3);
  const TruthScan ts = make_scan(lidar, world, at_rest(base), 0);
  LidarPipelineParams pp = pipeline_params(lp);
  pp.keep_points = true;
  LidarPipeline pipeline(pp);
  const LidarResult res = pipeline.process(ts.scan, nullptr);
  ASSERT_TRUE(res.ok) << res.status;
  // the simulator's scan is in column / ring order with no bad return, so the
  // pipeline's points are the scan's, in the same order
  ASSERT_EQ(res.points.size(), ts.cone.size());

  std::size_t ground = 0, ground_ok = 0, cone_pts = 0, cone_kept = 0, cone_in_cones = 0;
  const Vec2 sensor = base.transform({lp.mount_x, lp.mount_y});
  for (std::size_t i = 0; i < ts.cone.size(); ++i) {
    const std::int32_t truth = ts.cone[i];
    const PointLabel label = res.points[i].label;
    if (truth == -1) {
      ++ground;
      if (label == PointLabel::Ground) ++ground_ok;
    } else if (distance(cones[static_cast<std::size_t>(truth)].position, sensor) <= 20.0) {
      ++cone_pts;
      if (label != PointLabel::Ground) ++cone_kept;
      if (label == PointLabel::Cone) ++cone_in_cones;
    }
  }
  const double g_rate = double(ground_ok) / double(ground);
  const double kept = double(cone_kept) / double(cone_pts);
  const double in_cones = double(cone_in_cones) / double(cone_pts);
  std::printf("%s: ground labelled ground %.4f (%zu of %zu); cone points within 20 m kept %.4f, "
              "in accepted cones %.4f (%zu points); %zu vertical, %zu reconstructed, %zu cones\n",
              gc.name, g_rate, ground_ok, ground, kept, in_cones, cone_pts, res.counts.vertical,
              res.counts.reconstructed, res.cones.size());
  std::printf("  %zu clusters; rejected: count %zu, size %zu, height %zu, shape %zu, density %zu\n",
              res.counts.clusters, res.counts.rejected_count, res.counts.rejected_size,
              res.counts.rejected_height, res.counts.rejected_shape, res.counts.rejected_density);
  EXPECT_GE(g_rate, gc.min_ground);
  EXPECT_GE(kept, gc.min_kept);
  EXPECT_GE(in_cones, gc.min_in_cones);
}

// measured (ground labelled ground / cone points within 20 m kept, i.e. not
// labelled ground / in accepted cones):
//   flat                     0.9958 / 0.979 / 0.976
//   slope 0.1                0.9862 / 0.963 / 0.742
//   bumps 0.1 m              0.9927 / 0.951 / 0.903
//   slope 0.1 + bumps 0.1 m  0.9788 / 0.940 / 0.673
// (the former 1 deg layout over -16 .. +15 deg: 0.9956 / 0.954 / 0.924,
// 0.9798 / 0.960 / 0.743, 0.9948 / 0.888 / 0.819, 0.9815 / 0.873 / 0.617)
// On slopes, ground far uphill (the sensor's upward rings graze it at 5-50 m)
// is judged against planes extrapolated from nearer regions, and the cones
// there lose returns to the ground or fail the height filter; a cone's
// lowest 2 cm always go with the ground.
INSTANTIATE_TEST_SUITE_P(
    Grounds, LidarGround,
    ::testing::Values(GroundCase{"flat", 0.0, 0.0, 0.0, 0.99, 0.93, 0.90},
                      GroundCase{"slope 0.1", 0.1, 0.0, 0.0, 0.975, 0.93, 0.70},
                      GroundCase{"bumps 0.1 m", 0.0, 0.0, 0.1, 0.99, 0.86, 0.78},
                      GroundCase{"slope 0.1 + bumps 0.1 m", 0.07, 0.07, 0.1, 0.975, 0.85, 0.58}),
    [](const ::testing::TestParamInfo<GroundCase>& param_info) {
      std::string s = param_info.param.name;
      std::string out;
      for (char c : s) out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
      return out;
    });

// ------------------------------------------------------------- colour

// blue and yellow cones scattered at 2 .. 10 m around a car at rest, many
// layouts; the colour of each detected cone against its truth, by range
struct ColourTally {
  int right = 0, wrong = 0, unknown = 0, missed = 0;
  int total() const { return right + wrong + unknown + missed; }
};

std::vector<ColourTally> colour_sweep(const sensors::LidarParams& lp, int layouts, double r_max) {
  std::vector<ColourTally> bands(5);  // 2-4, 4-6, 6-8, 8-10, 10+
  std::mt19937_64 rng(77);
  std::uniform_real_distribution<double> radius(2.0, r_max), angle(-kPi, kPi);
  LidarPipeline pipeline(pipeline_params(lp));
  sensors::Lidar lidar(lp, 9);
  for (int l = 0; l < layouts; ++l) {
    const Pose2 base{0.0, 0.0, angle(rng)};
    const Vec2 sensor = base.transform({lp.mount_x, lp.mount_y});
    std::vector<Cone> cones;
    while (cones.size() < 24) {
      const Vec2 p = sensor + unit_from_angle(angle(rng)) * radius(rng);
      bool clear = true;
      for (const Cone& c : cones) clear = clear && distance(c.position, p) > 2.0;
      // keep the line of sight clear: no cone within 0.6 m of the ray to another
      for (const Cone& c : cones) {
        const Vec2 a = c.position - sensor, b = p - sensor;
        const Vec2 near = norm(a) < norm(b) ? a : b, far = norm(a) < norm(b) ? b : a;
        const double along = dot(near, far / norm(far));
        if (along > 0.0 && std::abs(cross(far / norm(far), near)) < 0.6) clear = false;
      }
      if (clear) cones.push_back({p, cones.size() % 2 == 0 ? ConeColor::Blue : ConeColor::Yellow});
    }
    sensors::LidarWorld world(cones);
    const TruthScan ts = make_scan(lidar, world, at_rest(base), 0);
    const LidarResult res = pipeline.process(ts.scan, nullptr);
    EXPECT_TRUE(res.ok) << res.status;
    std::vector<Vec2> truth;
    for (const Cone& c : cones) truth.push_back(in_base(base, c.position));
    const Match m = match(truth, xy_of(res.cones), 0.3);
    for (std::size_t t = 0; t < cones.size(); ++t) {
      const double d = distance(cones[t].position, sensor);
      ColourTally& band = bands[std::min<std::size_t>(4, static_cast<std::size_t>(std::max(0.0, (d - 2.0) / 2.0)))];
      const int k = m.detection_of[t];
      if (k < 0) {
        ++band.missed;
      } else if (res.cones[static_cast<std::size_t>(k)].color == cones[t].color) {
        ++band.right;
      } else if (res.cones[static_cast<std::size_t>(k)].color == ConeColor::Unknown) {
        ++band.unknown;
      } else {
        ++band.wrong;
      }
    }
  }
  return bands;
}

void print_bands(const char* what, const std::vector<ColourTally>& bands) {
  const char* names[] = {"2-4 m", "4-6 m", "6-8 m", "8-10 m", "10+ m"};
  for (std::size_t b = 0; b < bands.size(); ++b) {
    const ColourTally& t = bands[b];
    if (t.total() == 0) continue;
    std::printf("%s %s: %d cones, right %.3f, wrong %.3f, unknown %.3f, missed %.3f\n", what, names[b],
                t.total(), double(t.right) / t.total(), double(t.wrong) / t.total(),
                double(t.unknown) / t.total(), double(t.missed) / t.total());
  }
}

// the sum of the bands [0, n)
ColourTally within(const std::vector<ColourTally>& bands, std::size_t n) {
  ColourTally t;
  for (std::size_t b = 0; b < n; ++b) {
    t.right += bands[b].right;
    t.wrong += bands[b].wrong;
    t.unknown += bands[b].unknown;
    t.missed += bands[b].missed;
  }
  return t;
}

// the issue: intensity colour at least 95 % right within 10 m, with the
// default sensor (32 channels, 0.5 deg over -8 .. +7.5 deg: three rings on a
// small cone out to ~11 m, one of them always in the stripe)
TEST(LidarPipelineTest, IntensityColourOfBlueAndYellowCones) {
  sensors::LidarParams lp;  // the default: 32 channels, 0.5 deg
  const std::vector<ColourTally> bands = colour_sweep(lp, 20, 10.0);
  print_bands("32 ch 0.5 deg", bands);
  // measured: right 0.985 / 1.000 / 1.000 / 0.994 at 2-4 / 4-6 / 6-8 / 8-10 m
  // (0.996 of 480 cones, never wrong); 0.998 - 0.999 over 960 cones of other
  // layouts, 0.86 at 10-14 m
  const ColourTally t = within(bands, 4);
  std::printf("32 ch 0.5 deg within 10 m: %d cones, right %.3f\n", t.total(), double(t.right) / t.total());
  EXPECT_GE(double(t.right) / t.total(), 0.95);
  for (std::size_t b = 0; b < 4; ++b) {
    EXPECT_GE(double(bands[b].right) / bands[b].total(), 0.95) << "band " << b;
  }
}

// why the default is not the wide 1 deg fan (32 channels over -16 .. +15 deg,
// the former default): beyond ~8 m only two rings (0.15 m and ~0.3 m above
// the ground) reach a small cone, no parabola, Unknown (but never wrong)
TEST(LidarPipelineTest, IntensityColourWideOneDegreeLayout) {
  sensors::LidarParams lp;
  lp.elevation_min = -16.0 * kPi / 180.0;
  lp.elevation_max = 15.0 * kPi / 180.0;
  const std::vector<ColourTally> bands = colour_sweep(lp, 20, 10.0);
  print_bands("32 ch 1 deg", bands);
  // measured: right 1.000 / 1.000 / 1.000 at 2-4 / 4-6 / 6-8 m, then 0.013
  // at 8-10 m (0.987 unknown, none wrong)
  const ColourTally within8 = within(bands, 3);
  EXPECT_GE(double(within8.right) / within8.total(), 0.95);
  EXPECT_LE(double(bands[3].wrong) / bands[3].total(), 0.02);
}

// a dense sensor over the wide field: 128 channels over -16 .. +15 deg
// (0.24 deg) also reaches >= 95 % within 10 m
TEST(LidarPipelineTest, IntensityColourDenseSensor) {
  sensors::LidarParams lp;
  lp.channels = 128;  // 0.24 deg
  lp.elevation_min = -16.0 * kPi / 180.0;
  lp.elevation_max = 15.0 * kPi / 180.0;
  const std::vector<ColourTally> bands = colour_sweep(lp, 20, 10.0);
  print_bands("128 ch", bands);
  // measured: right 1.000 / 1.000 / 1.000 / 0.987 by 2 m band out to 10 m
  const ColourTally t = within(bands, 4);
  EXPECT_GE(double(t.right) / t.total(), 0.95);
}

// ------------------------------------------------------------- a real track

world::TrackModel fsg_2023() {
  const std::string path = std::string(PADDOCK_SOURCE_DIR) + "/tracks/fsg_2023.csv";
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return world::build_track(world::parse_track(text.str(), path));
}

TEST(LidarPipelineTest, FsgTrackPrecisionRecallAndPositionError) {
  const world::TrackModel track = fsg_2023();
  ASSERT_GT(track.cones.size(), 100u);
  sensors::LidarParams lp;  // default noise
  sensors::LidarWorld world(track.cones);
  sensors::Lidar lidar(lp, 21);
  LidarPipeline pipeline(pipeline_params(lp));
  const double kRange = 15.0, kGate = 0.3;
  int tp = 0, truths = 0, dets = 0, colour_right = 0, colour_decided = 0;
  double err = 0.0, err_max = 0.0;
  const std::size_t n = track.centreline.size();
  for (std::size_t k = 0; k < 8; ++k) {
    const std::size_t i = k * n / 8;
    const Vec2 p = track.centreline[i], q = track.centreline[(i + 1) % n];
    const Pose2 base{p.x, p.y, angle_of(q - p)};
    const TruthScan ts = make_scan(lidar, world, at_rest(base), from_seconds(double(k)));
    const LidarResult res = pipeline.process(ts.scan, nullptr);
    ASSERT_TRUE(res.ok) << res.status;
    const Vec2 sensor{lp.mount_x, lp.mount_y};
    std::vector<Vec2> truth, det;
    std::vector<ConeColor> truth_colour, det_colour;
    for (const Cone& c : track.cones) {
      const Vec2 b = in_base(base, c.position);
      if (distance(b, sensor) <= kRange) {
        truth.push_back(b);
        truth_colour.push_back(c.color);
      }
    }
    // detections in range; a cone just beyond the range may be detected
    // just inside it: those match truth within range + gate and count neither way
    std::vector<Vec2> truth_wide;
    for (const Cone& c : track.cones) {
      const Vec2 b = in_base(base, c.position);
      if (distance(b, sensor) <= kRange + kGate) truth_wide.push_back(b);
    }
    for (const ConeCandidate& c : res.cones) {
      const Vec2 b{c.centre.x(), c.centre.y()};
      if (distance(b, sensor) <= kRange) {
        det.push_back(b);
        det_colour.push_back(c.color);
      }
    }
    const Match m = match(truth, det, kGate);
    const Match mw = match(truth_wide, det, kGate);
    tp += m.true_positives;
    truths += m.truths;
    dets += m.detections - (mw.true_positives - m.true_positives);
    err += m.error_sum;
    err_max = std::max(err_max, m.error_max);
    for (std::size_t t = 0; t < truth.size(); ++t) {
      const int d = m.detection_of[t];
      if (d < 0 || det_colour[static_cast<std::size_t>(d)] == ConeColor::Unknown) continue;
      ++colour_decided;
      if (det_colour[static_cast<std::size_t>(d)] == truth_colour[t]) ++colour_right;
    }
  }
  const double precision = double(tp) / dets, recall = double(tp) / truths, mean = err / tp;
  std::printf("FSG 2023, 8 poses, within %.0f m: precision %.3f, recall %.3f (%d of %d cones, %d "
              "detections), mean position error %.3f m (max %.3f); colour decided %d, right %d\n",
              kRange, precision, recall, tp, truths, dets, mean, err_max, colour_decided, colour_right);
  EXPECT_GE(precision, 0.9);
  EXPECT_GE(recall, 0.9);
  EXPECT_LT(mean, 0.1);
}

// the free-space boundary (LidarResult::free_range) on FSG 2023 among the
// venue's barriers, 3 m outside the boundary cones, against a 2-D ray cast
// of the blocks' footprints done here: per 1-degree bin, the nearest block
// face over 20 rays across the bin. Cones never count as obstacles (the
// same track without barriers gives no finite bin at all).
double ray_to_block(Vec2 dir, const std::vector<world::Block>& blocks) {
  double best = std::numeric_limits<double>::infinity();
  for (const world::Block& b : blocks) {
    const std::vector<Vec2> c = world::block_corners(b);
    for (std::size_t i = 0; i < c.size(); ++i) {
      const Vec2 p = c[i], q = c[(i + 1) % c.size()], e = q - p;
      const double den = dir.x * e.y - dir.y * e.x;  // ray t dir = p + s e
      if (std::abs(den) < 1e-12) continue;
      const double t = (p.x * e.y - p.y * e.x) / den;
      const double u = (p.x * dir.y - p.y * dir.x) / den;
      if (t > 0.0 && u >= 0.0 && u <= 1.0) best = std::min(best, t);
    }
  }
  return best;
}

TEST(LidarPipelineTest, FreeRangeIsTheNearestBarrierAndNeverACone) {
  const world::TrackModel track = fsg_2023();
  world::VenueParams vp;
  vp.barrier_offset = 3.0;
  const std::vector<world::Block> blocks = world::venue_blocks(track, track.cones, vp);
  ASSERT_GT(blocks.size(), 100u);
  sensors::LidarParams lp;
  sensors::LidarWorld with(track.cones, {}, {}, blocks), without(track.cones);
  sensors::Lidar lidar(lp, 22);
  LidarPipeline pipeline(pipeline_params(lp));
  const std::size_t bins = static_cast<std::size_t>(LidarPipelineParams{}.free_range_bins);
  int compared = 0, agree = 0, phantom = 0, finite = 0, finite_without = 0;
  const std::size_t n = track.centreline.size();
  for (std::size_t k = 0; k < 8; ++k) {
    const std::size_t i = k * n / 8;
    const Vec2 p = track.centreline[i], q = track.centreline[(i + 1) % n];
    const Pose2 base{p.x, p.y, angle_of(q - p)};
    const LidarResult bare = pipeline.process(make_scan(lidar, without, at_rest(base), 0).scan, nullptr);
    ASSERT_TRUE(bare.ok) << bare.status;
    ASSERT_EQ(bare.free_range.size(), bins);
    for (float f : bare.free_range) finite_without += std::isfinite(f);
    const LidarResult res = pipeline.process(make_scan(lidar, with, at_rest(base), 0).scan, nullptr);
    ASSERT_TRUE(res.ok) << res.status;
    ASSERT_EQ(res.free_range.size(), bins);
    // the blocks in the base frame
    std::vector<world::Block> local = blocks;
    for (world::Block& b : local) {
      b.centre = base.inverse_transform(b.centre);
      b.yaw -= base.yaw;
    }
    for (std::size_t j = 0; j < bins; ++j) {
      double truth = std::numeric_limits<double>::infinity();
      for (int r = 0; r < 20; ++r) {
        const double bearing = -kPi + (static_cast<double>(j) + (r + 0.5) / 20.0) * 2.0 * kPi / static_cast<double>(bins);
        truth = std::min(truth, ray_to_block(unit_from_angle(bearing), local));
      }
      const double f = res.free_range[j];
      finite += std::isfinite(f);
      if (std::isfinite(f) && f < truth - 0.25) ++phantom;
      // a barrier 6-25 m away stands in the beams above 0.6 m and in range
      if (truth >= 6.0 && truth <= 25.0) {
        ++compared;
        agree += std::abs(f - truth) <= 0.25;
      }
    }
  }
  std::printf("free range on FSG 2023 among barriers, 8 poses: %d of %d bins with a barrier 6-25 m away "
              "agree within 0.25 m; %d of %d finite bins nearer than any barrier; %d finite bins without barriers\n",
              agree, compared, phantom, finite, finite_without);
  EXPECT_EQ(finite_without, 0) << "a cone is never an obstacle";
  ASSERT_GT(compared, 200);
  EXPECT_GE(agree, 0.9 * compared);
  EXPECT_LE(phantom, finite / 100);
}

// ------------------------------------------------------------- bad data

TEST(LidarPipelineTest, EmptyAndNanScansGiveACleanStatus) {
  sensors::LidarParams lp;
  LidarPipeline pipeline(pipeline_params(lp));
  const double nan = std::numeric_limits<double>::quiet_NaN();

  hal::LidarScan empty;
  empty.stamp = 5;
  empty.end = 10;
  LidarResult r = pipeline.process(empty, nullptr);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.status.find("empty"), std::string::npos) << r.status;
  EXPECT_TRUE(r.cones.empty());
  EXPECT_EQ(r.stamp, 10);

  hal::LidarScan nans;
  const auto fnan = static_cast<float>(nan);
  for (int i = 0; i < 1000; ++i) {
    nans.points.push_back({fnan, 1.0f, fnan, 0.5f, static_cast<std::uint16_t>(i % 32), i / 32});
  }
  r = pipeline.process(nans, nullptr);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.counts.invalid_dropped, 1000u);
  EXPECT_NE(r.status.find("no usable points"), std::string::npos) << r.status;

  // a real scan with NaNs, infinities and bad rings sprinkled in: the same
  // cones as without them
  const Pose2 base{0.0, 0.0, 0.0};
  std::vector<Cone> cones = {{{8.0, 1.5}, ConeColor::Blue}, {{8.0, -1.5}, ConeColor::Yellow},
                             {{4.0, 1.5}, ConeColor::Blue}, {{4.0, -1.5}, ConeColor::Yellow}};
  sensors::LidarWorld world(cones);
  sensors::Lidar lidar(lp, 4);
  const TruthScan ts = make_scan(lidar, world, at_rest(base), 0);
  const LidarResult clean = pipeline.process(ts.scan, nullptr);
  hal::LidarScan dirty = ts.scan;
  std::vector<hal::LidarPoint> mixed;
  for (std::size_t i = 0; i < dirty.points.size(); ++i) {
    mixed.push_back(dirty.points[i]);
    if (i % 7 == 0) {
      hal::LidarPoint bad = dirty.points[i];
      switch (i % 4) {
        case 0: bad.x = fnan; break;
        case 1: bad.z = std::numeric_limits<float>::infinity(); break;
        case 2: bad.intensity = fnan; break;
        default: bad.ring = 200; break;
      }
      mixed.push_back(bad);
    }
  }
  dirty.points = mixed;
  const LidarResult r2 = pipeline.process(dirty, nullptr);
  ASSERT_TRUE(r2.ok) << r2.status;
  EXPECT_GT(r2.counts.invalid_dropped, 0u);
  EXPECT_EQ(r2.counts.points_in, mixed.size());
  ASSERT_EQ(r2.cones.size(), clean.cones.size());
  EXPECT_EQ(clean.cones.size(), 4u);
  for (std::size_t k = 0; k < clean.cones.size(); ++k) {
    EXPECT_EQ(r2.cones[k].centre, clean.cones[k].centre);
  }

  // a single point, and points out of order: no crash, a clean result
  hal::LidarScan one;
  one.points.push_back({1.0f, 0.0f, -0.15f, 0.1f, 3, 0});
  EXPECT_TRUE(pipeline.process(one, nullptr).ok);
  hal::LidarScan shuffled = ts.scan;
  std::reverse(shuffled.points.begin(), shuffled.points.end());
  const LidarResult r3 = pipeline.process(shuffled, nullptr);
  ASSERT_TRUE(r3.ok);
  ASSERT_EQ(r3.cones.size(), clean.cones.size());
}

TEST(LidarPipelineTest, ValidateNamesTheField) {
  LidarPipelineParams p;
  EXPECT_EQ(params::validate(p), "");
  p.ground.max_slope = -1.0;
  EXPECT_EQ(params::validate(p), "ground.max_slope must be > 0 (got -1)");
  p = LidarPipelineParams{};
  p.ground.region_bounds = {3.0, 2.0};
  EXPECT_EQ(params::validate(p), "ground.region_bounds must be ascending (item 1)");
  p.ground.region_bounds = {2.0, -3.0};
  EXPECT_EQ(params::validate(p), "ground.region_bounds[1] must be > 0 m (got -3)");
  p = LidarPipelineParams{};
  p.clustering.tolerance = 0.0;
  EXPECT_EQ(params::validate(p), "clustering.tolerance must be > 0 m (got 0)");
  p = LidarPipelineParams{};
  p.cone.max_count_ratio = 0.1;
  EXPECT_EQ(params::validate(p), "cone.max_count_ratio must be > min_count_ratio");
  p = LidarPipelineParams{};
  p.colour.min_layers = 2;
  EXPECT_EQ(params::validate(p), "colour.min_layers must be >= 3 (got 2)");
  p = LidarPipelineParams{};
  p.colour.big_cone_height = 0.5;
  EXPECT_EQ(params::validate(p), "colour.big_cone_height must equal cone.big_cone_height (got 0.5 and 0.42)");
  p = LidarPipelineParams{};
  p.calibration.channels = 0;
  EXPECT_EQ(params::validate(p), "calibration.channels must be in [1, 65535] (got 0)");
  EXPECT_THROW(LidarPipeline{p}, std::invalid_argument);
}

// ------------------------------------------------------------- determinism

TEST(LidarPipelineTest, SameInputGivesIdenticalOutput) {
  const world::TrackModel track = fsg_2023();
  sensors::LidarParams lp;
  sensors::LidarWorld world(track.cones);
  sensors::Lidar lidar(lp, 8);
  const Pose2 base = track.start;
  const TruthScan a = make_scan(lidar, world, at_rest(base), 0);
  const TruthScan b = make_scan(lidar, world, at_rest(Pose2{base.x + 20.0, base.y, base.yaw}), 0);
  LidarPipelineParams pp = pipeline_params(lp);
  pp.keep_points = true;
  LidarPipeline p1(pp), p2(pp);
  const LidarResult r1 = p1.process(a.scan, nullptr);
  p2.process(b.scan, nullptr);  // dirty the scratch buffers first
  const LidarResult r2 = p2.process(a.scan, nullptr);
  const LidarResult r3 = p1.process(a.scan, nullptr);
  for (const LidarResult* r : {&r2, &r3}) {
    ASSERT_EQ(r->cones.size(), r1.cones.size());
    for (std::size_t k = 0; k < r1.cones.size(); ++k) {
      EXPECT_EQ(r->cones[k].centre, r1.cones[k].centre);
      EXPECT_EQ(r->cones[k].color, r1.cones[k].color);
      EXPECT_EQ(r->cones[k].points, r1.cones[k].points);
    }
    ASSERT_EQ(r->points.size(), r1.points.size());
    for (std::size_t i = 0; i < r1.points.size(); ++i) {
      ASSERT_EQ(r->points[i].label, r1.points[i].label);
      ASSERT_EQ(r->points[i].x, r1.points[i].x);
    }
    EXPECT_EQ(r->counts.ground, r1.counts.ground);
    EXPECT_EQ(r->status, r1.status);
  }
  EXPECT_GT(r1.cones.size(), 5u);
}

}  // namespace
}  // namespace paddock::perception
