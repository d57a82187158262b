#pragma once
// LiDAR-camera fusion (paper, "Sensor Fusion"): the LiDAR pipeline's cone
// candidates are projected into the camera image (camera_model.h, the
// paper's [x y w]^T = K [R|T] [X Y Z 1]^T), and
//   - outside the camera's view (behind it, off the image, or farther than
//     FusionParams::camera_range from its optical centre): kept, with the
//     LiDAR's (intensity profile) colour -- the LiDAR's wider field of view
//     is used alone there;
//   - in view and inside a detector box (grown by box_margin px on every
//     side): kept, with the box's colour; if several boxes hold it, the one
//     whose centre column is nearest its column (cones stand side by side
//     more often than on top of each other);
//   - in view but in no box: dropped as a false detection of the LiDAR.
//
// The candidates must be in the base frame at the camera's exposure time (the
// caller moves them there from the scan's reference time). ConeCandidate's
// centre is "the cluster's centre" (types.h): it is projected as given, plus
// FusionParams::height_offset along base z (0 by default: a cluster's centre
// already lies around mid-height of the cone; set it to half a cone's height
// if the centres come at the base).
//
// Pure library: no I/O, never throws.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "autonomy/common/params.h"
#include "autonomy/perception/types.h"

namespace paddock::perception {

struct FusionParams {
  // at the default detector (detector.h) a cone is missed 9 % of the time at
  // 15 m and 43 % at 20 m: each miss would drop a real cone
  double camera_range = 15.0;
  // the boxes' jitter (a pixel or two) and the cluster centre's offset from
  // the cone's axis (a few cm: 1-3 px at 10 m)
  double box_margin = 3.0;
  // see the top
  double height_offset = 0.0;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(camera_range), {"m", params::in(0.1, 200.0),
                                    "beyond this the camera is not trusted (LiDAR only): the point counts as outside the camera's view"});
    v(PADDOCK_PARAM(box_margin), {"px", params::in(0.0, 100.0), "a projected centre this far outside a box is in it"});
    v(PADDOCK_PARAM(height_offset), {"m", params::any(), "added to the candidate centre's z before projecting"});
  }
};

enum class FusionSource {
  Camera,   // in view and in a box: the box's colour
  Lidar,    // out of view: the LiDAR's colour
  Dropped,  // in view, in no box: a false detection (or a non-finite centre)
};

const char* to_string(FusionSource s);

struct FusedCone {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // m, base frame, as given
  bool kept = false;
  ConeColor color = ConeColor::Unknown;  // final colour (Dropped: the LiDAR's)
  FusionSource source = FusionSource::Lidar;
  // the projected point (px) when the candidate is in front of the camera
  bool projected = false;
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();
  int box = -1;  // index into the boxes (Camera only)
};

struct FusionResult {
  std::vector<FusedCone> cones;  // one per candidate, in their order
  int from_camera = 0, from_lidar = 0, dropped = 0;
};

// the rule above for each candidate. A candidate with a non-finite centre is
// dropped.
FusionResult fuse(const std::vector<ConeCandidate>& candidates_at_camera_time,
                  const std::vector<BoundingBox>& boxes, const CameraCalibration& calib,
                  const FusionParams& params = {});

}  // namespace paddock::perception
