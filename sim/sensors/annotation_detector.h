#pragma once
// the simulator's cone detector node: what a network on the car (the paper's
// YOLOv5 trained on FSOCO) would post through the HAL for one camera frame
// (hal::CameraDetections), made from the frame's annotation
// (CameraAnnotation, camera.h), which only the simulation knows. It takes the
// tight pixel box of every annotated instance and spoils it with a seeded
// error model of a network (DetectorParams): misses that grow with range and
// occlusion, class confusion, box jitter, a smallest box.
//
// The car's side of the seam is perception::ConeDetector (a network run by
// perception itself on hal::CameraFrame) or a detector node of its own that
// posts hal::CameraDetections; this one is the latter, run by the simulator's
// back end.
//
// Model (DetectorParams) + a small class holding its random stream
// (AnnotationDetector). No I/O, no clock. detect() never throws; a frame it
// cannot use gives ok = false and a reason.
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "autonomy/common/params.h"
#include "autonomy/hal/messages.h"
#include "sim/sensors/camera.h"
#include "sim/sensors/gaussian.h"

namespace paddock::sensors {

// the error model. Each annotated instance (a cone with >= 1 labelled pixel)
// is missed with
//   p_miss = 1 - (1 - p_range(range)) (1 - p_occlusion(visible_fraction))
//   p_range(r) = p_miss_near + (1 - p_miss_near) s(x),
//     x = clamp((r - range_full) / (range_max - range_full), 0, 1), s(x) = 3x^2 - 2x^3
//     (flat p_miss_near up to range_full, rising smoothly to 1 at range_max)
//   p_occlusion(f) = 1 for f < visible_min, (visible_full - f) / (visible_full
//     - visible_min) in between, 0 from visible_full up
// and is dropped outright when its tight box is less than min_box_height px
// tall. A detected cone's class flips blue <-> yellow with p_confuse_blue_yellow
// and small <-> big orange with p_confuse_orange_size; its box edges move by
// independent N(0, (box_jitter w)^2) (left, right) and N(0, (box_jitter h)^2)
// (top, bottom), w and h the tight box's size, then are clamped to the image.
// confidence = 1 - p_miss.
//
// The defaults are for the simulator's default camera (800 x 500 px, fx = 400
// px, camera.h), where a small cone (0.325 m) is f h / r = 130 / r
// px tall: 10.8 px at 12 m, 6.5 px at 20 m. A YOLOv5 at this input size finds
// nearly every whole cone of 10 px and up and few below 6 px (FS teams report
// reliable detection to 15-20 m on ~1 MP images); the curve below gives 2 %
// to 12 m, 9.3 % at 15 m, 43 % at 20 m, 1 at 30 m.
struct DetectorParams {
  double p_miss_near = 0.02;
  double range_full = 12.0;
  double range_max = 30.0;
  // a cone less than 30 % visible is not found, one 70 % visible always is
  // (as far as occlusion goes): YOLO finds well-separated half-hidden cones
  // about half the time
  double visible_min = 0.3;
  double visible_full = 0.7;
  // blue and yellow look alike in low light / against the sun; the two
  // oranges differ mainly in size
  double p_confuse_blue_yellow = 0.01;
  double p_confuse_orange_size = 0.05;
  // 3 %: about a pixel on a 30 px cone, YOLO's typical IoU of 0.85-0.9 on cones
  double box_jitter = 0.03;
  // YOLOv5's smallest anchors
  double min_box_height = 6.0;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(p_miss_near), {"", params::fraction(), "chance of missing an unoccluded cone up to range_full"});
    v(PADDOCK_PARAM(range_full), {"m", params::at_least(0.0), "misses start to grow beyond this"});
    v(PADDOCK_PARAM(range_max), {"m", params::above(0.0), "every cone is missed beyond this"});
    v(PADDOCK_PARAM(visible_min), {"", params::fraction(), "a cone less visible than this is always missed"});
    v(PADDOCK_PARAM(visible_full), {"", params::fraction(), "occlusion adds no misses above this visible share"});
    v(PADDOCK_PARAM(p_confuse_blue_yellow), {"", params::fraction(), "chance of calling blue yellow or yellow blue"});
    v(PADDOCK_PARAM(p_confuse_orange_size), {"", params::fraction(), "chance of calling a small orange big or a big one small"});
    v(PADDOCK_PARAM(box_jitter), {"", params::fraction(), "std of each box edge as a share of the box size"});
    v(PADDOCK_PARAM(min_box_height), {"px", params::at_least(0.0), "smaller boxes are never found"});
  }
  std::string check() const {
    if (!(range_max > range_full)) return "range_max must be > range_full";
    if (!(visible_full >= visible_min)) return "visible_full must be >= visible_min";
    return "";
  }
};

// p_miss of the model above, for an instance at `range` (m) with
// `visible_fraction` (-) visible
double miss_probability(const DetectorParams& p, double range, double visible_fraction);

// the tight box of an instance's labelled pixels: [i_min, i_max + 1) x
// [j_min, j_max + 1) in px (pixel (i, j) covers [i, i+1) x [j, j+1))
struct TightBox {
  std::int32_t id = -1;
  int i_min = 0, i_max = -1, j_min = 0, j_max = -1;
  int pixels = 0;
};

// the tight boxes of the annotation's instances (in annotation.instances'
// order, one per instance, pixels = 0 for one with no labelled pixel); "" in
// *error or the reason the frame cannot be read (then the result is empty).
// From the annotation's list of labelled pixels when it has one (the
// camera's), else from every label
std::vector<TightBox> tight_boxes(const hal::CameraFrame& frame, const CameraAnnotation& annotation,
                                  std::string* error);

// what the detector made of one frame: when ok, the detections message to post
struct AnnotationDetection {
  bool ok = false;
  std::string reason;                // why not ok ("" when ok)
  hal::CameraDetections detections;  // the frame's stamp and size, the boxes (ok)
};

class AnnotationDetector {
 public:
  // throws std::invalid_argument when params::validate(params) fails. The seed starts
  // the detector's own random stream (std::mt19937_64).
  AnnotationDetector(const DetectorParams& params, std::uint64_t seed);

  // the boxes of the frame's annotated instances, in the order of
  // annotation.instances (missed and too small ones left out), stamped with
  // the frame's exposure and sized as the frame. Not ok: a frame with no
  // pixels, sizes that disagree (rgb != 3 w h, labels != w h), labels < -1 or
  // without an instance, duplicate or negative instance ids; and a frame
  // without annotation (labels empty), which this detector cannot see into.
  // Each instance takes the same number of draws from the stream whatever
  // becomes of it.
  AnnotationDetection detect(const hal::CameraFrame& frame, const CameraAnnotation& annotation);

  const DetectorParams& params() const { return params_; }

 private:
  DetectorParams params_;
  std::mt19937_64 rng_;
  std::uniform_real_distribution<double> uniform_{0.0, 1.0};
  Gaussian normal_{0.0, 1.0};
};

}  // namespace paddock::sensors
