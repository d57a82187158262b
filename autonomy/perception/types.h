#pragma once
// the values that pass between the perception pipeline's stages: the LiDAR
// pipeline's cone candidates, the camera detector's boxes, and the sensors'
// calibration the stack is told (the same numbers the simulator's sensors use,
// or the car's calibration files).
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "autonomy/common/cone.h"
#include "autonomy/common/geometry.h"
#include "autonomy/hal/lidar_layout.h"
#include "autonomy/hal/messages.h"

namespace paddock::perception {

// where the LiDAR sits and how its beams are laid out: the sensor's own
// layout and mounting (one struct with the simulated sensor's, hal/lidar_layout.h)
using LidarCalibration = hal::LidarLayout;

// the pinhole camera: intrinsics K and extrinsics [R|T] = T_camera_base (the
// base frame into the camera's optical frame: z forward, x right, y down)
struct CameraCalibration {
  int width = 0, height = 0;  // px
  double fx = 0.0, fy = 0.0;  // px
  double cx = 0.0, cy = 0.0;  // px
  Eigen::Isometry3d T_camera_base = Eigen::Isometry3d::Identity();
};

// a cone found by the LiDAR pipeline: its cluster's centre in the base frame
// at the scan's reference time (the rotation's end, motion-corrected)
struct ConeCandidate {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // m, base frame
  ConeColor color = ConeColor::Unknown;              // from the intensity profile (Unknown: undecided)
  int points = 0;                                    // in the (reconstructed) cluster
};

// one box of the camera detector, in pixels (x right, y down, row 0 at the
// top): the HAL's box, as a detector node posts it or ConeDetector returns it
using BoundingBox = hal::CameraBox;

}  // namespace paddock::perception
