#pragma once
// the camera's cone detector (paper, "Camera Perception"): boxes around the
// cones of an image, each with one of the FSOCO classes (blue, yellow, small
// orange, big orange; unknown for FSOCO's "unknown cone").
//
// ConeDetector is the interface a real network (the paper's YOLOv5 trained on
// FSOCO) implements on the car, for a Perception that runs it on the camera
// frames itself. A detector node of its own posts its boxes through the HAL
// instead (hal::CameraDetections); the simulator's stand-in, which reads the
// simulation's annotation of a frame, is such a node
// (sim/sensors/annotation_detector.h).
//
// Pure library: no I/O, no clock, no simulator types. detect() never throws;
// a frame it cannot use gives ok = false and a reason.
#include <string>
#include <vector>

#include "autonomy/hal/messages.h"
#include "autonomy/perception/types.h"

namespace paddock::perception {

struct DetectorResult {
  bool ok = false;
  std::string reason;               // why not ok ("" when ok)
  std::vector<BoundingBox> boxes;   // px, the image convention of camera_model.h
};

class ConeDetector {
 public:
  virtual ~ConeDetector();
  virtual DetectorResult detect(const hal::CameraFrame& frame) = 0;
};

}  // namespace paddock::perception
