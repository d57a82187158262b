// the pinhole projection against numbers worked out by hand from
// [x y w]^T = K [R|T] [X Y Z 1]^T (paper, "Sensor Fusion").
#include "autonomy/perception/camera_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace paddock::perception {
namespace {

// fx 500, fy 480, cx 320, cy 240 (640 x 480); R the base -> optical axes of a
// level camera (x_c = -Y, y_c = -Z, z_c = X), T = (0.1, 0.5, -0.2)
CameraCalibration hand_calibration() {
  CameraCalibration c;
  c.width = 640;
  c.height = 480;
  c.fx = 500.0;
  c.fy = 480.0;
  c.cx = 320.0;
  c.cy = 240.0;
  Eigen::Matrix3d R;
  R << 0, -1, 0,  //
      0, 0, -1,   //
      1, 0, 0;
  c.T_camera_base.linear() = R;
  c.T_camera_base.translation() = Eigen::Vector3d(0.1, 0.5, -0.2);
  return c;
}

TEST(CameraModel, KnownPointProjectsToTheHandComputedPixel) {
  const CameraCalibration c = hand_calibration();
  // P = (10, 2, 1): [R|T] P = (-2 + 0.1, -1 + 0.5, 10 - 0.2) = (-1.9, -0.5, 9.8)
  // K: x = 500 (-1.9) + 320 (9.8) = 2186, y = 480 (-0.5) + 240 (9.8) = 2112, w = 9.8
  const auto uv = project(c, Eigen::Vector3d(10.0, 2.0, 1.0));
  ASSERT_TRUE(uv.has_value());
  EXPECT_NEAR(uv->x(), 2186.0 / 9.8, 1e-9);  // 223.061...
  EXPECT_NEAR(uv->y(), 2112.0 / 9.8, 1e-9);  // 215.510...
  EXPECT_TRUE(in_image(c, *uv));
  // the optical axis (x_c = y_c = 0): Y = 0.1, Z = 0.5, any X > 0.2 -> (cx, cy)
  const auto axis = project(c, Eigen::Vector3d(3.0, 0.1, 0.5));
  ASSERT_TRUE(axis.has_value());
  EXPECT_NEAR(axis->x(), 320.0, 1e-12);
  EXPECT_NEAR(axis->y(), 240.0, 1e-12);
  // to_camera is [R|T] alone
  const Eigen::Vector3d pc = to_camera(c, Eigen::Vector3d(10.0, 2.0, 1.0));
  EXPECT_NEAR(pc.x(), -1.9, 1e-12);
  EXPECT_NEAR(pc.y(), -0.5, 1e-12);
  EXPECT_NEAR(pc.z(), 9.8, 1e-12);
}

TEST(CameraModel, RotatedCameraByHand) {
  // a camera yawed 90 deg left: optical z = base +Y, x_c = +X (right of it), y_c = -Z
  CameraCalibration c = hand_calibration();
  Eigen::Matrix3d R;
  R << 1, 0, 0,  //
      0, 0, -1,  //
      0, 1, 0;
  c.T_camera_base.linear() = R;
  c.T_camera_base.translation().setZero();
  // P = (1, 4, -0.5): (1, 0.5, 4) -> u = 500 / 4 + 320 = 445, v = 480 0.5 / 4 + 240 = 300
  const auto uv = project(c, Eigen::Vector3d(1.0, 4.0, -0.5));
  ASSERT_TRUE(uv.has_value());
  EXPECT_NEAR(uv->x(), 445.0, 1e-9);
  EXPECT_NEAR(uv->y(), 300.0, 1e-9);
  // a point straight ahead of the base is beside this camera (depth 0)
  EXPECT_FALSE(project(c, Eigen::Vector3d(5.0, 0.0, 0.0)).has_value());
}

TEST(CameraModel, BehindOnTheCentreAndNonFiniteHaveNoImage) {
  const CameraCalibration c = hand_calibration();
  // depth z_c = X - 0.2
  EXPECT_FALSE(project(c, Eigen::Vector3d(-5.0, 0.0, 0.0)).has_value());
  EXPECT_FALSE(project(c, Eigen::Vector3d(0.2, 1.0, 1.0)).has_value());          // depth 0
  EXPECT_FALSE(project(c, Eigen::Vector3d(0.2 + 1e-7, 1.0, 1.0)).has_value());   // below the epsilon
  EXPECT_TRUE(project(c, Eigen::Vector3d(0.2 + 1e-3, 0.1, 0.5)).has_value());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(project(c, Eigen::Vector3d(nan, 0.0, 0.0)).has_value());
  EXPECT_FALSE(project(c, Eigen::Vector3d(5.0, std::numeric_limits<double>::infinity(), 0.0)).has_value());
}

TEST(CameraModel, InImageIsHalfOpen) {
  const CameraCalibration c = hand_calibration();
  EXPECT_TRUE(in_image(c, {0.0, 0.0}));
  EXPECT_TRUE(in_image(c, {639.999, 479.999}));
  EXPECT_FALSE(in_image(c, {640.0, 10.0}));
  EXPECT_FALSE(in_image(c, {10.0, 480.0}));
  EXPECT_FALSE(in_image(c, {-0.001, 10.0}));
  EXPECT_FALSE(in_image(c, {10.0, -0.001}));
  // a point far to the side projects off the image
  const auto uv = project(c, Eigen::Vector3d(2.0, 5.0, 0.5));
  ASSERT_TRUE(uv.has_value());
  EXPECT_FALSE(in_image(c, *uv));
}

}  // namespace
}  // namespace paddock::perception
