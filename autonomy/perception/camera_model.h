#pragma once
// the pinhole projection the LiDAR-camera fusion uses (paper, "Sensor Fusion"):
//   [x y w]^T = K [R|T] [X Y Z 1]^T,  (u, v) = (x / w, y / w)
// with K = [fx 0 cx; 0 fy cy; 0 0 1] and [R|T] = CameraCalibration::T_camera_base
// (base frame -> optical frame: z forward, x right, y down). No distortion:
// the frames the detector sees are undistorted (paper, "Camera Perception").
//
// Image coordinates (px): u right, v down; pixel (i, j) (column i, row j, row 0
// at the top) covers [i, i+1) x [j, j+1), so its centre is (i + 0.5, j + 0.5)
// and the image is [0, width) x [0, height). The simulator's camera
// (sim/sensors/camera.h) renders with exactly this convention.
#include <optional>

#include <Eigen/Core>

#include "autonomy/perception/types.h"

namespace paddock::perception {

// a point whose depth along the optical axis is at most this is behind the
// camera (or on its centre) and has no image
inline constexpr double kMinProjectionDepth = 1e-6;  // m

// the point p_base (base frame, m) in the camera's optical frame
Eigen::Vector3d to_camera(const CameraCalibration& calib, const Eigen::Vector3d& p_base);

// the image point (u, v) of p_base (base frame, m); nullopt when its depth
// z_camera <= kMinProjectionDepth or anything is not finite
std::optional<Eigen::Vector2d> project(const CameraCalibration& calib, const Eigen::Vector3d& p_base);

// true when (u, v) lies on the image: 0 <= u < width and 0 <= v < height
bool in_image(const CameraCalibration& calib, const Eigen::Vector2d& uv);

}  // namespace paddock::perception
