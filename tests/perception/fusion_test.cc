// the fusion rule of the paper's "Sensor Fusion" on hand-placed boxes (each
// case of the rule and its edges), then on a frame of the simulator's camera
// with its own calibration.
#include "autonomy/perception/fusion.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "autonomy/perception/camera_model.h"
#include "sim/sensors/annotation_detector.h"
#include "sim/sensors/camera.h"

namespace paddock::perception {
namespace {

// a level camera at the base origin: x_c = -Y, y_c = -Z, z_c = X; f = 100,
// 200 x 100 px, centre (100, 50). A base point (X, Y, Z) lands at
// u = 100 - 100 Y / X, v = 50 - 100 Z / X.
CameraCalibration level_camera() {
  CameraCalibration c;
  c.width = 200;
  c.height = 100;
  c.fx = c.fy = 100.0;
  c.cx = 100.0;
  c.cy = 50.0;
  Eigen::Matrix3d R;
  R << 0, -1, 0,  //
      0, 0, -1,   //
      1, 0, 0;
  c.T_camera_base.linear() = R;
  return c;
}

BoundingBox box(double x0, double y0, double x1, double y1, ConeColor c) {
  BoundingBox b;
  b.x_min = x0;
  b.y_min = y0;
  b.x_max = x1;
  b.y_max = y1;
  b.color = c;
  return b;
}

ConeCandidate cand(double x, double y, double z, ConeColor c = ConeColor::Unknown) {
  ConeCandidate k;
  k.centre = Eigen::Vector3d(x, y, z);
  k.color = c;
  k.points = 10;
  return k;
}

TEST(Fusion, TheThreeCasesOfTheRule) {
  const CameraCalibration cam = level_camera();
  // (10, 0, 0) -> (100, 50); (10, 2, 0) -> (80, 50); (5, -1, -0.5) -> (120, 60)
  const std::vector<BoundingBox> boxes = {box(95, 40, 105, 60, ConeColor::Yellow),
                                          box(115, 55, 125, 70, ConeColor::BigOrange)};
  const std::vector<ConeCandidate> c = {
      cand(10, 0, 0, ConeColor::Blue),       // in the yellow box: the camera's colour
      cand(5, -1, -0.5, ConeColor::Unknown),  // in the orange box
      cand(10, 2, 0, ConeColor::Blue),       // in view, in no box: dropped
      cand(-4, 0, 0, ConeColor::Yellow),     // behind: the LiDAR's colour
      cand(2, 5, 0, ConeColor::Blue),        // u = -150: off the image
      cand(16, 0, 0, ConeColor::Yellow),     // 16 m > camera_range 15 m
  };
  const FusionResult r = fuse(c, boxes, cam, FusionParams{});
  ASSERT_EQ(r.cones.size(), 6u);
  EXPECT_EQ(r.from_camera, 2);
  EXPECT_EQ(r.from_lidar, 3);
  EXPECT_EQ(r.dropped, 1);

  EXPECT_TRUE(r.cones[0].kept);
  EXPECT_EQ(r.cones[0].source, FusionSource::Camera);
  EXPECT_EQ(r.cones[0].color, ConeColor::Yellow);
  EXPECT_EQ(r.cones[0].box, 0);
  EXPECT_TRUE(r.cones[0].projected);
  EXPECT_NEAR(r.cones[0].pixel.x(), 100.0, 1e-9);
  EXPECT_NEAR(r.cones[0].pixel.y(), 50.0, 1e-9);

  EXPECT_EQ(r.cones[1].source, FusionSource::Camera);
  EXPECT_EQ(r.cones[1].color, ConeColor::BigOrange);
  EXPECT_NEAR(r.cones[1].pixel.x(), 120.0, 1e-9);
  EXPECT_NEAR(r.cones[1].pixel.y(), 60.0, 1e-9);

  EXPECT_FALSE(r.cones[2].kept);
  EXPECT_EQ(r.cones[2].source, FusionSource::Dropped);
  EXPECT_NEAR(r.cones[2].pixel.x(), 80.0, 1e-9);

  for (int k : {3, 4, 5}) {
    EXPECT_TRUE(r.cones[k].kept) << k;
    EXPECT_EQ(r.cones[k].source, FusionSource::Lidar) << k;
    EXPECT_EQ(r.cones[k].color, c[k].color) << k;
    EXPECT_EQ(r.cones[k].box, -1) << k;
  }
  EXPECT_FALSE(r.cones[3].projected);
  EXPECT_TRUE(r.cones[4].projected);
  EXPECT_NEAR(r.cones[4].pixel.x(), -150.0, 1e-9);
  EXPECT_EQ(r.cones[0].centre, c[0].centre);
}

TEST(Fusion, MarginNearestBoxHeightOffsetAndRange) {
  const CameraCalibration cam = level_camera();
  // (10, 0, 0) -> (100, 50): 2 px right of a box ending at 98 (margin 3: in),
  // 4 px right of one ending at 96 (out)
  FusionParams p;
  EXPECT_EQ(fuse({cand(10, 0, 0)}, {box(90, 40, 98, 60, ConeColor::Blue)}, cam, p).from_camera, 1);
  EXPECT_EQ(fuse({cand(10, 0, 0)}, {box(90, 40, 96, 60, ConeColor::Blue)}, cam, p).dropped, 1);
  p.box_margin = 0.0;
  EXPECT_EQ(fuse({cand(10, 0, 0)}, {box(90, 40, 98, 60, ConeColor::Blue)}, cam, p).dropped, 1);
  // two boxes hold it: the one whose centre column is nearest (101 vs 95)
  p = FusionParams{};
  const FusionResult two = fuse({cand(10, 0, 0)},
                                {box(80, 30, 110, 70, ConeColor::Blue), box(96, 45, 106, 55, ConeColor::Yellow)}, cam, p);
  EXPECT_EQ(two.cones[0].box, 1);
  EXPECT_EQ(two.cones[0].color, ConeColor::Yellow);
  // height offset: the centre given at the base (z = -0.3) plus 0.3 m lands at v = 50
  p.height_offset = 0.3;
  const FusionResult h = fuse({cand(10, 0, -0.3)}, {box(95, 48, 105, 52, ConeColor::Blue)}, cam, p);
  EXPECT_NEAR(h.cones[0].pixel.y(), 50.0, 1e-9);
  EXPECT_EQ(h.cones[0].source, FusionSource::Camera);
  // camera_range: 12 m is in view at 15 m, out at 10 m
  p = FusionParams{};
  EXPECT_EQ(fuse({cand(12, 0, 0)}, {}, cam, p).dropped, 1);
  p.camera_range = 10.0;
  EXPECT_EQ(fuse({cand(12, 0, 0)}, {}, cam, p).from_lidar, 1);
}

TEST(Fusion, EdgeInputs) {
  const CameraCalibration cam = level_camera();
  EXPECT_TRUE(fuse({}, {}, cam).cones.empty());
  const FusionResult r = fuse({cand(std::numeric_limits<double>::quiet_NaN(), 0, 0, ConeColor::Blue)}, {}, cam);
  ASSERT_EQ(r.cones.size(), 1u);
  EXPECT_EQ(r.cones[0].source, FusionSource::Dropped);
  EXPECT_EQ(r.dropped, 1);
  // an unset calibration (0 x 0 image): nothing is in view, all LiDAR
  const FusionResult u = fuse({cand(5, 0, 0, ConeColor::Yellow)}, {}, CameraCalibration{});
  EXPECT_EQ(u.from_lidar, 1);
  EXPECT_EQ(params::validate(FusionParams{}), "");
  FusionParams bad;
  bad.camera_range = 0.0;
  EXPECT_EQ(params::validate(bad), "camera_range must be in [0.1, 200] m (got 0)");
  EXPECT_STREQ(to_string(FusionSource::Dropped), "dropped");
}

TEST(Fusion, OnARenderedFrameWithTheCamerasCalibration) {
  // cones ahead, a perfect detector on the simulator's frame; the LiDAR
  // candidates carry no colour (Unknown) except the one beside the car
  const std::vector<Cone> cones = {{{5.0, 1.6}, ConeColor::Blue},     {{5.0, -1.6}, ConeColor::Yellow},
                                   {{9.0, 1.8}, ConeColor::Blue},     {{9.0, -1.4}, ConeColor::Yellow},
                                   {{12.0, 2.5}, ConeColor::BigOrange}, {{1.0, 3.0}, ConeColor::Yellow}};
  sensors::LidarWorld world(cones);
  sensors::Camera camera(sensors::CameraParams{}, 1);
  const sensors::AnnotatedFrame shot = camera.render(world, Pose2{}, 0);
  sensors::DetectorParams perfect;
  perfect.p_miss_near = 0.0;
  perfect.p_confuse_blue_yellow = 0.0;
  perfect.p_confuse_orange_size = 0.0;
  perfect.box_jitter = 0.0;
  const sensors::AnnotationDetection det = sensors::AnnotationDetector(perfect, 1).detect(shot.frame, shot.annotation);
  ASSERT_TRUE(det.ok);
  ASSERT_EQ(det.detections.boxes.size(), 5u);  // the one beside the car is out of view

  // candidates: cluster centres at 40 % of a cone's height (a cluster's centroid
  // sits a little below mid-height), a few cm off the axis
  std::vector<ConeCandidate> cands;
  for (std::size_t i = 0; i < 5; ++i) {
    const double h = cones[i].color == ConeColor::BigOrange ? 0.505 : 0.325;
    cands.push_back(cand(cones[i].position.x - 0.03, cones[i].position.y + 0.02, 0.4 * h));
  }
  cands.push_back(cand(1.0, 3.0, 0.13, ConeColor::Yellow));  // beside the car: outside the FoV
  cands.push_back(cand(7.0, 0.0, 0.13));                     // in view, no cone there: fake
  cands.push_back(cand(7.0, -7.5, 0.13));                    // off the right edge: u = 400 + 400 7.5 / 6.05 = 896
  const FusionResult r = fuse(cands, det.detections.boxes, camera.calibration());
  ASSERT_EQ(r.cones.size(), 8u);
  for (std::size_t i = 0; i < 5; ++i) {
    EXPECT_EQ(r.cones[i].source, FusionSource::Camera) << i;
    EXPECT_EQ(r.cones[i].color, cones[i].color) << i;
  }
  EXPECT_EQ(r.cones[5].source, FusionSource::Lidar);
  EXPECT_EQ(r.cones[5].color, ConeColor::Yellow);
  EXPECT_FALSE(r.cones[5].projected && in_image(camera.calibration(), r.cones[5].pixel));
  EXPECT_EQ(r.cones[6].source, FusionSource::Dropped);
  EXPECT_TRUE(in_image(camera.calibration(), r.cones[6].pixel));
  EXPECT_EQ(r.cones[7].source, FusionSource::Lidar);
  EXPECT_EQ(r.from_camera, 5);
  EXPECT_EQ(r.from_lidar, 2);
  EXPECT_EQ(r.dropped, 1);
}

}  // namespace
}  // namespace paddock::perception
