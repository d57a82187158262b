// the annotation detector on hand-made annotated frames (exact tight boxes),
// its error model against the configured curve (binomial tolerances over many
// draws), and the frames it must refuse.
#include "sim/sensors/annotation_detector.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "sim/sensors/camera.h"
#include "sim/world/track.h"

namespace paddock::sensors {
namespace {

// a w x h frame (grey), no cones
AnnotatedFrame blank(int w = 120, int h = 90) {
  AnnotatedFrame f;
  f.frame.stamp = 42;
  f.frame.width = w;
  f.frame.height = h;
  f.frame.rgb.assign(3 * static_cast<std::size_t>(w) * h, 100);
  f.annotation.labels.assign(static_cast<std::size_t>(w) * h, -1);
  return f;
}

// label the pixels of [i0, i1] x [j0, j1] with id (a solid block)
void paint(AnnotatedFrame& f, std::int32_t id, int i0, int i1, int j0, int j1) {
  for (int j = j0; j <= j1; ++j) {
    for (int i = i0; i <= i1; ++i) f.annotation.labels[static_cast<std::size_t>(j) * f.frame.width + i] = id;
  }
}

// the detector's boxes on f (the detections message's), or none when it refuses f
struct Result {
  bool ok = false;
  std::string reason;
  std::vector<hal::CameraBox> boxes;
};

Result run(AnnotationDetector& d, const AnnotatedFrame& f) {
  AnnotationDetection r = d.detect(f.frame, f.annotation);
  if (r.ok) {
    // the message is the frame's: its exposure, its size
    EXPECT_EQ(r.detections.stamp, f.frame.stamp);
    EXPECT_EQ(r.detections.width, f.frame.width);
    EXPECT_EQ(r.detections.height, f.frame.height);
  } else {
    EXPECT_TRUE(r.detections.boxes.empty());
  }
  return {r.ok, r.reason, std::move(r.detections.boxes)};
}
Result run(AnnotationDetector&& d, const AnnotatedFrame& f) { return run(d, f); }

CameraInstance inst(std::int32_t id, ConeColor c, double range, double vf = 1.0) {
  CameraInstance k;
  k.id = id;
  k.color = c;
  k.range = range;
  k.visible_fraction = vf;
  return k;
}

DetectorParams perfect() {
  DetectorParams p;
  p.p_miss_near = 0.0;
  p.range_full = 1e6;
  p.range_max = 2e6;
  p.visible_min = 0.0;
  p.visible_full = 0.0;
  p.p_confuse_blue_yellow = 0.0;
  p.p_confuse_orange_size = 0.0;
  p.box_jitter = 0.0;
  p.min_box_height = 0.0;
  return p;
}

TEST(AnnotationDetector, NoErrorsGivesTheTightBoxesAndClasses) {
  AnnotatedFrame f = blank();
  // a cone-like blob: a narrow top on a wider base, id 7
  paint(f, 7, 50, 52, 20, 29);
  paint(f, 7, 47, 55, 30, 41);
  // a block, id 3, partly covered by a block of id 9 in front
  paint(f, 3, 10, 19, 60, 79);
  paint(f, 9, 15, 30, 70, 85);
  f.annotation.instances = {inst(7, ConeColor::Blue, 5.0), inst(3, ConeColor::SmallOrange, 8.0, 0.6),
                 inst(9, ConeColor::BigOrange, 4.0), inst(11, ConeColor::Yellow, 6.0)};  // 11: no pixels
  AnnotationDetector d(perfect(), 1);
  const Result r = run(d, f);
  ASSERT_TRUE(r.ok) << r.reason;
  ASSERT_EQ(r.boxes.size(), 3u);
  // pixel (i, j) covers [i, i+1) x [j, j+1): box [i_min, i_max + 1) x [j_min, j_max + 1)
  EXPECT_EQ(r.boxes[0].x_min, 47.0);
  EXPECT_EQ(r.boxes[0].x_max, 56.0);
  EXPECT_EQ(r.boxes[0].y_min, 20.0);
  EXPECT_EQ(r.boxes[0].y_max, 42.0);
  EXPECT_EQ(r.boxes[0].color, ConeColor::Blue);
  EXPECT_EQ(r.boxes[1].x_min, 10.0);
  EXPECT_EQ(r.boxes[1].x_max, 20.0);
  EXPECT_EQ(r.boxes[1].y_min, 60.0);
  EXPECT_EQ(r.boxes[1].y_max, 80.0);  // id 9 covers its right part of rows 70..79
  EXPECT_EQ(r.boxes[1].color, ConeColor::SmallOrange);
  EXPECT_EQ(r.boxes[2].x_min, 15.0);
  EXPECT_EQ(r.boxes[2].x_max, 31.0);
  EXPECT_EQ(r.boxes[2].y_min, 70.0);
  EXPECT_EQ(r.boxes[2].y_max, 86.0);
  EXPECT_EQ(r.boxes[2].color, ConeColor::BigOrange);
  EXPECT_DOUBLE_EQ(r.boxes[0].confidence, 1.0);
}

TEST(AnnotationDetector, TightBoxesAgreeWithABruteForceScanOfScatteredLabels) {
  // single labelled pixels and small blobs at random places (row ends, block
  // edges, a width no multiple of 16): each box and pixel count as a plain
  // min/max over every pixel gives it
  std::mt19937 rng(11);
  for (const int w : {37, 64, 803}) {
    AnnotatedFrame f = blank(w, 23);
    const int ids = 6;
    for (int id = 0; id < ids; ++id) f.annotation.instances.push_back(CameraInstance{id, ConeColor::Blue, 5.0, 1.0});
    std::uniform_int_distribution<int> col(0, w - 1), row(0, 22), which(0, ids - 2), size(0, 2);
    for (int k = 0; k < 60; ++k) {
      const int i = col(rng), j = row(rng), s = size(rng);
      paint(f, which(rng), i, std::min(w - 1, i + s), j, std::min(22, j + s));
    }
    // the last instance: one pixel in the last column
    paint(f, ids - 1, w - 1, w - 1, 22, 22);
    std::string error;
    const std::vector<TightBox> boxes = tight_boxes(f.frame, f.annotation, &error);
    ASSERT_TRUE(error.empty()) << error;
    ASSERT_EQ(boxes.size(), static_cast<std::size_t>(ids));
    for (int id = 0; id < ids; ++id) {
      int i_min = w, i_max = -1, j_min = 23, j_max = -1, pixels = 0;
      for (int j = 0; j < 23; ++j)
        for (int i = 0; i < w; ++i)
          if (f.annotation.labels[static_cast<std::size_t>(j) * w + i] == id) {
            i_min = std::min(i_min, i), i_max = std::max(i_max, i), j_min = std::min(j_min, j), j_max = std::max(j_max, j);
            ++pixels;
          }
      const TightBox& b = boxes[static_cast<std::size_t>(id)];
      EXPECT_EQ(b.id, id);
      EXPECT_EQ(b.pixels, pixels) << w << " " << id;
      if (pixels == 0) continue;
      EXPECT_EQ(b.i_min, i_min) << w << " " << id;
      EXPECT_EQ(b.i_max, i_max) << w << " " << id;
      EXPECT_EQ(b.j_min, j_min) << w << " " << id;
      EXPECT_EQ(b.j_max, j_max) << w << " " << id;
    }
  }
}

// the camera lists the pixels it labelled: the tight boxes from that list
// are those of a scan of every label, over frames along FSG 2023; and a
// list that names an unlabelled pixel or one out of the frame is malformed
TEST(AnnotationDetector, TheCamerasListOfLabelledPixelsGivesTheBoxesOfAFullScan) {
  std::ifstream in(std::string(PADDOCK_SOURCE_DIR) + "/tracks/fsg_2023.csv");
  std::stringstream text;
  text << in.rdbuf();
  const world::TrackModel track = world::build_track(world::parse_track(text.str(), "fsg_2023"));
  const LidarWorld world(track.cones);
  Camera cam(CameraParams{}, 1);
  hal::CameraFrame frame;
  CameraAnnotation annotation;
  const std::size_t m = track.centreline.size();
  std::size_t boxes_seen = 0;
  for (int s = 0; s < 20; ++s) {
    const std::size_t i = m * static_cast<std::size_t>(s) / 20;
    const Vec2 a = track.centreline[i], b = track.centreline[(i + 4) % m];
    cam.render(world, Pose2{a.x, a.y, angle_of(b - a)}, s, frame, annotation);
    ASSERT_TRUE(annotation.listed);
    CameraAnnotation scanned = annotation;
    scanned.listed = false;
    std::string e1, e2;
    const std::vector<TightBox> listed = tight_boxes(frame, annotation, &e1), full = tight_boxes(frame, scanned, &e2);
    ASSERT_TRUE(e1.empty() && e2.empty()) << e1 << e2;
    ASSERT_EQ(listed.size(), full.size());
    for (std::size_t k = 0; k < full.size(); ++k) {
      EXPECT_EQ(listed[k].id, full[k].id);
      EXPECT_EQ(listed[k].pixels, full[k].pixels) << s << " " << k;
      if (full[k].pixels == 0) continue;
      ++boxes_seen;
      EXPECT_EQ(listed[k].i_min, full[k].i_min);
      EXPECT_EQ(listed[k].i_max, full[k].i_max);
      EXPECT_EQ(listed[k].j_min, full[k].j_min);
      EXPECT_EQ(listed[k].j_max, full[k].j_max);
    }
  }
  EXPECT_GT(boxes_seen, 400u);
  CameraAnnotation bad = annotation;
  bad.labelled.push_back(0);  // the top-left pixel: sky, unlabelled
  std::string error;
  EXPECT_TRUE(tight_boxes(frame, bad, &error).empty());
  EXPECT_NE(error.find("listed pixel"), std::string::npos) << error;
  bad.labelled.back() = static_cast<std::uint32_t>(annotation.labels.size());
  EXPECT_TRUE(tight_boxes(frame, bad, &error).empty());
  EXPECT_NE(error.find("listed pixel"), std::string::npos) << error;
}

TEST(AnnotationDetector, MissCurveIsTheDocumentedOne) {
  const DetectorParams p;  // 2 %, 12 m .. 30 m, 0.3 .. 0.7
  // by hand: x = (r - 12) / 18, s = 3x^2 - 2x^3, p = 0.02 + 0.98 s
  EXPECT_NEAR(miss_probability(p, 5.0, 1.0), 0.02, 1e-12);
  EXPECT_NEAR(miss_probability(p, 12.0, 1.0), 0.02, 1e-12);
  EXPECT_NEAR(miss_probability(p, 15.0, 1.0), 0.0925926, 1e-6);  // s(1/6) = 0.0740741
  EXPECT_NEAR(miss_probability(p, 21.0, 1.0), 0.51, 1e-12);      // s(1/2) = 1/2
  EXPECT_NEAR(miss_probability(p, 24.0, 1.0), 0.7459259, 1e-6);  // s(2/3) = 20/27
  EXPECT_NEAR(miss_probability(p, 30.0, 1.0), 1.0, 1e-12);
  EXPECT_NEAR(miss_probability(p, 45.0, 1.0), 1.0, 1e-12);
  // occlusion: 1 - 0.98 (1 - p_occ)
  EXPECT_NEAR(miss_probability(p, 5.0, 0.29), 1.0, 1e-12);
  EXPECT_NEAR(miss_probability(p, 5.0, 0.5), 1.0 - 0.98 * 0.5, 1e-12);
  EXPECT_NEAR(miss_probability(p, 5.0, 0.6), 1.0 - 0.98 * 0.75, 1e-12);
  EXPECT_NEAR(miss_probability(p, 5.0, 0.7), 0.02, 1e-12);
}

// the observed miss fraction of instances at (range, visible fraction) over
// n frames, each frame holding one instance per case
void expect_miss_rates(const std::vector<std::pair<double, double>>& cases, const std::vector<double>& expected) {
  AnnotatedFrame f = blank(200, 40);
  for (std::size_t k = 0; k < cases.size(); ++k) {
    const int i0 = 2 + 20 * static_cast<int>(k);
    paint(f, static_cast<std::int32_t>(k), i0, i0 + 10, 5, 30);
    f.annotation.instances.push_back(
        inst(static_cast<std::int32_t>(k), ConeColor::Blue, cases[k].first, cases[k].second));
  }
  DetectorParams p;
  p.min_box_height = 0.0;
  AnnotationDetector d(p, 2024);
  const int n = 4000;
  std::vector<int> found(cases.size(), 0);
  for (int t = 0; t < n; ++t) {
    const Result r = run(d, f);
    ASSERT_TRUE(r.ok);
    // the boxes come in instance order; identify them by their column
    for (const hal::CameraBox& b : r.boxes) ++found[static_cast<std::size_t>((b.x_min + b.x_max) / 2.0 / 20.0)];
  }
  for (std::size_t k = 0; k < cases.size(); ++k) {
    const double q = expected[k], rate = 1.0 - static_cast<double>(found[k]) / n;
    const double tol = 4.0 * std::sqrt(q * (1.0 - q) / n) + 1e-9;  // 4 sigma of a binomial
    EXPECT_NEAR(rate, q, tol) << "range " << cases[k].first << " visible " << cases[k].second;
  }
}

TEST(AnnotationDetector, MissRateFollowsRangeAndOcclusion) {
  expect_miss_rates({{5.0, 1.0}, {15.0, 1.0}, {21.0, 1.0}, {24.0, 1.0}, {31.0, 1.0}},
                    {0.02, 0.0925926, 0.51, 0.7459259, 1.0});
  expect_miss_rates({{5.0, 0.2}, {5.0, 0.5}, {5.0, 0.6}, {5.0, 0.9}, {21.0, 0.5}},
                    {1.0, 0.51, 0.265, 0.02, 1.0 - 0.49 * 0.5});
}

TEST(AnnotationDetector, ClassConfusionRates) {
  DetectorParams p = perfect();
  p.p_confuse_blue_yellow = 0.2;
  p.p_confuse_orange_size = 0.3;
  AnnotatedFrame f = blank(200, 40);
  const ConeColor colours[] = {ConeColor::Blue, ConeColor::Yellow, ConeColor::SmallOrange, ConeColor::BigOrange,
                               ConeColor::Unknown};
  for (int k = 0; k < 5; ++k) {
    paint(f, k, 2 + 20 * k, 12 + 20 * k, 5, 30);
    f.annotation.instances.push_back(inst(k, colours[k], 5.0));
  }
  AnnotationDetector d(p, 99);
  const int n = 4000;
  int flipped[5] = {0, 0, 0, 0, 0};
  const ConeColor other[] = {ConeColor::Yellow, ConeColor::Blue, ConeColor::BigOrange, ConeColor::SmallOrange,
                             ConeColor::Unknown};
  for (int t = 0; t < n; ++t) {
    const Result r = run(d, f);
    ASSERT_EQ(r.boxes.size(), 5u);
    for (int k = 0; k < 5; ++k) {
      if (k < 4) {
        ASSERT_TRUE(r.boxes[k].color == colours[k] || r.boxes[k].color == other[k]);
      } else {
        ASSERT_EQ(r.boxes[k].color, ConeColor::Unknown);
      }
      flipped[k] += r.boxes[k].color != colours[k];
    }
  }
  const double q[] = {0.2, 0.2, 0.3, 0.3, 0.0};
  for (int k = 0; k < 5; ++k) {
    EXPECT_NEAR(static_cast<double>(flipped[k]) / n, q[k], 4.0 * std::sqrt(q[k] * (1 - q[k]) / n) + 1e-9) << k;
  }
}

TEST(AnnotationDetector, BoxJitterHasTheConfiguredSpreadAndSmallBoxesAreDropped) {
  DetectorParams p = perfect();
  p.box_jitter = 0.1;
  AnnotatedFrame f = blank(200, 120);
  paint(f, 1, 80, 99, 30, 69);  // 20 x 40 px: std 2 px across, 4 px along
  f.annotation.instances.push_back(inst(1, ConeColor::Blue, 5.0));
  AnnotationDetector d(p, 5);
  const int n = 4000;
  double s[4] = {0, 0, 0, 0}, s2[4] = {0, 0, 0, 0};
  for (int t = 0; t < n; ++t) {
    const Result r = run(d, f);
    ASSERT_EQ(r.boxes.size(), 1u);
    const double e[4] = {r.boxes[0].x_min - 80.0, r.boxes[0].x_max - 100.0, r.boxes[0].y_min - 30.0,
                         r.boxes[0].y_max - 70.0};
    for (int k = 0; k < 4; ++k) {
      s[k] += e[k];
      s2[k] += e[k] * e[k];
    }
  }
  const double sd[4] = {2.0, 2.0, 4.0, 4.0};
  for (int k = 0; k < 4; ++k) {
    const double mean = s[k] / n, var = s2[k] / n - mean * mean;
    EXPECT_NEAR(mean, 0.0, 4.0 * sd[k] / std::sqrt(n)) << k;
    // the sample variance's std is about var sqrt(2 / n)
    EXPECT_NEAR(var, sd[k] * sd[k], 4.0 * sd[k] * sd[k] * std::sqrt(2.0 / n)) << k;
  }
  // a 5 px tall box is below 6 px and never found; a 6 px one is
  DetectorParams q = perfect();
  q.min_box_height = 6.0;
  AnnotatedFrame g = blank();
  paint(g, 1, 10, 13, 10, 14);
  paint(g, 2, 30, 33, 10, 15);
  g.annotation.instances = {inst(1, ConeColor::Blue, 20.0), inst(2, ConeColor::Yellow, 20.0)};
  const Result r = run(AnnotationDetector(q, 1), g);
  ASSERT_TRUE(r.ok);
  ASSERT_EQ(r.boxes.size(), 1u);
  EXPECT_EQ(r.boxes[0].color, ConeColor::Yellow);
}

TEST(AnnotationDetector, HardwareEmptyAndMalformedFrames) {
  AnnotationDetector d(DetectorParams{}, 1);
  // a frame without annotation (as a hardware camera gives it): pixels only
  AnnotatedFrame hw = blank();
  hw.annotation.labels.clear();
  Result r = run(d, hw);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.reason.find("annotation"), std::string::npos) << r.reason;
  // no cones: ok, nothing
  r = run(d, blank());
  EXPECT_TRUE(r.ok) << r.reason;
  EXPECT_TRUE(r.boxes.empty());
  // malformed
  AnnotatedFrame bad = blank();
  bad.frame.rgb.pop_back();
  r = run(d, bad);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.reason.find("rgb"), std::string::npos) << r.reason;
  bad = blank();
  bad.annotation.labels.resize(10);
  EXPECT_FALSE(run(d, bad).ok);
  bad = blank();
  paint(bad, 4, 1, 2, 1, 2);  // label without instance
  r = run(d, bad);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.reason.find("no instance"), std::string::npos) << r.reason;
  bad = blank();
  bad.annotation.instances = {inst(2, ConeColor::Blue, 3.0), inst(2, ConeColor::Blue, 3.0)};
  EXPECT_FALSE(run(d, bad).ok);
  bad = blank();
  bad.annotation.labels[5] = -3;
  EXPECT_FALSE(run(d, bad).ok);
  EXPECT_FALSE(run(d, AnnotatedFrame{}).ok);
  bad = blank();
  bad.frame.width = -4;
  EXPECT_FALSE(run(d, bad).ok);
}

TEST(AnnotationDetector, ParamsValidation) {
  DetectorParams p;
  EXPECT_EQ(params::validate(p), "");
  p.range_max = p.range_full;
  EXPECT_NE(params::validate(p).find("range_max"), std::string::npos);
  p = DetectorParams{};
  p.visible_full = 0.1;
  EXPECT_NE(params::validate(p).find("visible_full"), std::string::npos);
  p = DetectorParams{};
  p.p_confuse_blue_yellow = 1.5;
  EXPECT_THROW(AnnotationDetector(p, 1), std::invalid_argument);
}

TEST(AnnotationDetector, DeterministicPerSeed) {
  AnnotatedFrame f = blank();
  for (int k = 0; k < 5; ++k) {
    paint(f, k, 2 + 20 * k, 12 + 20 * k, 5, 30);
    f.annotation.instances.push_back(inst(k, ConeColor::Blue, 10.0 + 3 * k, 0.5 + 0.1 * k));
  }
  AnnotationDetector a(DetectorParams{}, 7), b(DetectorParams{}, 7);
  for (int t = 0; t < 50; ++t) {
    const Result ra = run(a, f), rb = run(b, f);
    ASSERT_EQ(ra.boxes.size(), rb.boxes.size());
    for (std::size_t k = 0; k < ra.boxes.size(); ++k) {
      EXPECT_EQ(ra.boxes[k].x_min, rb.boxes[k].x_min);
      EXPECT_EQ(ra.boxes[k].y_max, rb.boxes[k].y_max);
      EXPECT_EQ(ra.boxes[k].color, rb.boxes[k].color);
    }
  }
}

TEST(AnnotationDetector, RenderedFrameGivesOneBoxPerVisibleCone) {
  // the simulator's camera: a gate of cones ahead, perfect detector
  const std::vector<Cone> cones = {{{6.0, 1.5}, ConeColor::Blue},
                                   {{6.0, -1.5}, ConeColor::Yellow},
                                   {{10.0, 1.7}, ConeColor::Blue},
                                   {{10.0, -1.3}, ConeColor::Yellow},
                                   {{8.0, -3.0}, ConeColor::BigOrange},
                                   {{-3.0, 0.0}, ConeColor::Blue}};  // behind the car
  sensors::LidarWorld world(cones);
  sensors::Camera cam(sensors::CameraParams{}, 1);
  const AnnotatedFrame f = cam.render(world, Pose2{}, 0);
  ASSERT_EQ(f.annotation.instances.size(), 5u);
  const Result r = run(AnnotationDetector(perfect(), 1), f);
  ASSERT_TRUE(r.ok);
  ASSERT_EQ(r.boxes.size(), 5u);
  const perception::CameraCalibration k = cam.calibration();
  for (std::size_t i = 0; i < 5; ++i) {
    EXPECT_EQ(r.boxes[i].color, cones[i].color);
    // the box holds the projection of the cone's mid-height point (by hand:
    // the camera 1.2 m up at x = 0.95, pitched 5 deg down, f = 400)
    const double h = cones[i].color == ConeColor::BigOrange ? 0.505 : 0.325;
    const double dx = cones[i].position.x - 0.95, dy = cones[i].position.y, dz = 0.5 * h - 1.2;
    const double th = 5.0 * kPi / 180.0;
    const double z = dx * std::cos(th) - dz * std::sin(th);
    const double u = 400.0 * -dy / z + 400.0, v = 400.0 * (-dx * std::sin(th) - dz * std::cos(th)) / z + 250.0;
    EXPECT_GT(u, r.boxes[i].x_min);
    EXPECT_LT(u, r.boxes[i].x_max);
    EXPECT_GT(v, r.boxes[i].y_min);
    EXPECT_LT(v, r.boxes[i].y_max);
    EXPECT_NEAR(r.boxes[i].y_max - r.boxes[i].y_min, k.fy * h / z, 3.0);
  }
}

}  // namespace
}  // namespace paddock::sensors
