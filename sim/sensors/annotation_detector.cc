#include "sim/sensors/annotation_detector.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

namespace paddock::sensors {


double miss_probability(const DetectorParams& p, double range, double visible_fraction) {
  if (!finite(range) || !finite(visible_fraction)) return 1.0;
  const double x = std::clamp((range - p.range_full) / (p.range_max - p.range_full), 0.0, 1.0);
  const double p_range = p.p_miss_near + (1.0 - p.p_miss_near) * x * x * (3.0 - 2.0 * x);
  double p_occ = 0.0;
  if (visible_fraction < p.visible_min) {
    p_occ = 1.0;
  } else if (visible_fraction < p.visible_full) {
    p_occ = (p.visible_full - visible_fraction) / (p.visible_full - p.visible_min);
  }
  return 1.0 - (1.0 - p_range) * (1.0 - p_occ);
}

std::vector<TightBox> tight_boxes(const hal::CameraFrame& f, const CameraAnnotation& a, std::string* error) {
  std::vector<TightBox> boxes;
  const auto fail = [&](const std::string& why) {
    if (error != nullptr) *error = why;
    return std::vector<TightBox>{};
  };
  if (error != nullptr) error->clear();
  if (f.width <= 0 || f.height <= 0) {
    std::ostringstream os;
    os << "frame has no pixels (" << f.width << " x " << f.height << ")";
    return fail(os.str());
  }
  const std::size_t n = static_cast<std::size_t>(f.width) * static_cast<std::size_t>(f.height);
  if (f.rgb.size() != 3 * n) {
    std::ostringstream os;
    os << "malformed frame: rgb has " << f.rgb.size() << " bytes, expected 3 x " << f.width << " x " << f.height;
    return fail(os.str());
  }
  if (a.labels.empty()) {
    return fail(
        "frame has no annotation: the annotation detector needs the simulation's labels and instances "
        "(a hardware camera gives none; the car needs a trained network)");
  }
  if (a.labels.size() != n) {
    std::ostringstream os;
    os << "malformed frame: " << a.labels.size() << " labels for " << f.width << " x " << f.height << " pixels";
    return fail(os.str());
  }
  std::unordered_map<std::int32_t, std::size_t> slot;
  boxes.resize(a.instances.size());
  for (std::size_t k = 0; k < a.instances.size(); ++k) {
    const std::int32_t id = a.instances[k].id;
    if (id < 0) return fail("malformed frame: instance with a negative id " + std::to_string(id));
    if (!slot.emplace(id, k).second) return fail("malformed frame: duplicate instance id " + std::to_string(id));
    boxes[k].id = id;
  }
  if (a.listed) {
    // the listed pixels alone: every labelled one, in no set order
    for (const std::uint32_t p : a.labelled) {
      const std::int32_t id = p < n ? a.labels[p] : -1;
      const auto it = id >= 0 ? slot.find(id) : slot.end();
      if (it == slot.end()) {
        std::ostringstream os;
        os << "malformed frame: listed pixel " << p << " has label " << id << " and no instance";
        return fail(os.str());
      }
      TightBox& t = boxes[it->second];
      const int i = static_cast<int>(p % static_cast<std::uint32_t>(f.width));
      const int j = static_cast<int>(p / static_cast<std::uint32_t>(f.width));
      if (t.pixels == 0) {
        t.i_min = t.i_max = i;
        t.j_min = t.j_max = j;
      } else {
        t.i_min = std::min(t.i_min, i);
        t.i_max = std::max(t.i_max, i);
        t.j_min = std::min(t.j_min, j);
        t.j_max = std::max(t.j_max, j);
      }
      ++t.pixels;
    }
    return boxes;
  }
  std::int32_t last_id = -1;
  TightBox* b = nullptr;
  // most pixels show no cone (-1, every bit set): a block of them whose
  // bitwise AND is still -1 holds no label and is skipped whole (a loop the
  // compiler vectorises)
  constexpr int kBlock = 16;
  for (int j = 0; j < f.height; ++j) {
    const std::int32_t* row = a.labels.data() + static_cast<std::size_t>(j) * static_cast<std::size_t>(f.width);
    for (int i = 0; i < f.width; ++i) {
      if (i % kBlock == 0 && i + kBlock <= f.width) {
        std::int32_t all = -1;
        for (int k = 0; k < kBlock; ++k) all &= row[i + k];
        if (all == -1) {
          i += kBlock - 1;
          continue;
        }
      }
      const std::int32_t id = row[i];
      if (id == -1) continue;
      if (id != last_id) {
        const auto it = slot.find(id);
        if (it == slot.end()) {
          std::ostringstream os;
          os << "malformed frame: label " << id << " at pixel (" << i << ", " << j << ") has no instance";
          return fail(os.str());
        }
        b = &boxes[it->second];
        last_id = id;
      }
      if (b->pixels == 0) {
        b->i_min = b->i_max = i;
        b->j_min = b->j_max = j;
      } else {
        b->i_min = std::min(b->i_min, i);
        b->i_max = std::max(b->i_max, i);
        b->j_max = j;  // rows ascend
      }
      ++b->pixels;
    }
  }
  return boxes;
}

AnnotationDetector::AnnotationDetector(const DetectorParams& params, std::uint64_t seed)
    : params_(params), rng_(seed) {
  params::require_valid(params_, "DetectorParams");
}

AnnotationDetection AnnotationDetector::detect(const hal::CameraFrame& frame, const CameraAnnotation& annotation) {
  AnnotationDetection r;
  const std::vector<TightBox> tight = tight_boxes(frame, annotation, &r.reason);
  if (!r.reason.empty()) return r;
  r.ok = true;
  r.detections.stamp = frame.stamp;
  r.detections.width = frame.width;
  r.detections.height = frame.height;
  const double w_img = frame.width, h_img = frame.height;
  for (std::size_t k = 0; k < tight.size(); ++k) {
    const TightBox& t = tight[k];
    const CameraInstance& inst = annotation.instances[k];
    if (t.pixels == 0) continue;
    // the same draws for every instance: miss, confusion, four edges
    const double u_miss = uniform_(rng_), u_conf = uniform_(rng_);
    double e[4];
    for (double& v : e) v = normal_(rng_);

    const double w = t.i_max + 1 - t.i_min, h = t.j_max + 1 - t.j_min;
    if (h < params_.min_box_height) continue;
    const double p_miss = miss_probability(params_, inst.range, inst.visible_fraction);
    if (u_miss < p_miss) continue;
    hal::CameraBox b;
    b.color = inst.color;
    const bool by = b.color == ConeColor::Blue || b.color == ConeColor::Yellow;
    const bool orange = b.color == ConeColor::SmallOrange || b.color == ConeColor::BigOrange;
    if ((by && u_conf < params_.p_confuse_blue_yellow) || (orange && u_conf < params_.p_confuse_orange_size)) {
      b.color = look_alike(b.color);
    }
    const double sx = params_.box_jitter * w, sy = params_.box_jitter * h;
    double x0 = std::clamp(t.i_min + sx * e[0], 0.0, w_img), x1 = std::clamp(t.i_max + 1 + sx * e[1], 0.0, w_img);
    double y0 = std::clamp(t.j_min + sy * e[2], 0.0, h_img), y1 = std::clamp(t.j_max + 1 + sy * e[3], 0.0, h_img);
    if (x0 > x1) std::swap(x0, x1);
    if (y0 > y1) std::swap(y0, y1);
    b.x_min = x0;
    b.x_max = x1;
    b.y_min = y0;
    b.y_max = y1;
    b.confidence = 1.0 - p_miss;
    r.detections.boxes.push_back(b);
  }
  return r;
}

}  // namespace paddock::sensors
