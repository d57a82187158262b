#include "autonomy/perception/motion_correction.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace paddock::perception {

namespace {

bool usable(const hal::LidarPoint& p, int channels) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) &&
         std::isfinite(p.intensity) && static_cast<int>(p.ring) < channels;
}

}  // namespace

std::string validate(const LidarCalibration& c) {
  std::ostringstream os;
  const double half_pi = 0.5 * kPi;
  if (!finite(c.mount_x) || !finite(c.mount_y)) {
    os << "mount_x and mount_y must be finite m";
  } else if (!finite(c.mount_z) || !(c.mount_z > 0.0)) {
    os << "mount_z must be finite and > 0 m (got " << c.mount_z << ")";
  } else if (!finite(c.mount_pitch) || !(std::abs(c.mount_pitch) < half_pi)) {
    os << "mount_pitch must be in (-pi/2, pi/2) rad (got " << c.mount_pitch << ")";
  } else if (c.channels < 1 || c.channels > 65535) {
    os << "channels must be in [1, 65535] (got " << c.channels << ")";
  } else if (!finite(c.elevation_min) || !(c.elevation_min > -half_pi)) {
    os << "elevation_min must be finite and > -pi/2 rad (got " << c.elevation_min << ")";
  } else if (!finite(c.elevation_max) || !(c.elevation_max < half_pi) ||
             !(c.elevation_max > c.elevation_min)) {
    os << "elevation_max must be in (elevation_min, pi/2) rad (got " << c.elevation_max << ")";
  } else if (c.columns < 1) {
    os << "columns must be >= 1 (got " << c.columns << ")";
  }
  return os.str();
}

MotionCorrector::MotionCorrector(const LidarCalibration& calibration) : calib_(calibration) {
  const std::string err = validate(calib_);
  if (!err.empty()) throw std::invalid_argument("LidarCalibration: " + err);
  cos_pitch_ = std::cos(calib_.mount_pitch);
  sin_pitch_ = std::sin(calib_.mount_pitch);
}

void MotionCorrector::correct(const hal::LidarScan& scan, const Odometry* odometry, Cloud& out) {
  out.stamp = scan.end;
  out.corrected = false;
  out.points_in = scan.points.size();
  out.invalid = 0;
  out.points.clear();
  out.columns.clear();

  // the valid points in (t, ring) order: a driver's scan already is (checked
  // in one pass), anything else is sorted once
  const std::vector<hal::LidarPoint>& in = scan.points;
  order_.clear();
  bool sorted = true;
  const hal::LidarPoint* prev = nullptr;
  for (std::size_t i = 0; i < in.size(); ++i) {
    const hal::LidarPoint& p = in[i];
    if (!usable(p, calib_.channels)) {
      ++out.invalid;
      continue;
    }
    if (prev != nullptr && (p.t < prev->t || (p.t == prev->t && p.ring <= prev->ring))) sorted = false;
    prev = &p;
    order_.push_back(static_cast<std::uint32_t>(i));
  }
  if (!sorted) {
    std::sort(order_.begin(), order_.end(), [&in](std::uint32_t a, std::uint32_t b) {
      if (in[a].t != in[b].t) return in[a].t < in[b].t;
      if (in[a].ring != in[b].ring) return in[a].ring < in[b].ring;
      return a < b;
    });
  }

  // columns: runs of equal time
  for (std::uint32_t k = 0; k < order_.size(); ++k) {
    const TimeNs t = in[order_[k]].t;
    if (out.columns.empty() || out.columns.back().t != t) out.columns.push_back({k, k, t});
    out.columns.back().end = k + 1;
  }

  // the motion of each column: the base at its time in the base at the end;
  // all columns or none (a partly corrected scan would tear)
  motion_.assign(out.columns.size(), Pose2{});
  if (odometry != nullptr && !out.columns.empty()) {
    bool covered = true;
    for (std::size_t c = 0; c < out.columns.size() && covered; ++c) {
      const std::optional<Pose2> T = odometry->relative(scan.end, out.columns[c].t);
      if (T) {
        motion_[c] = *T;
      } else {
        covered = false;
      }
    }
    out.corrected = covered;
    if (!covered) std::fill(motion_.begin(), motion_.end(), Pose2{});
  }

  // lidar -> levelled sensor -> base at the column's time -> base at the end
  out.points.resize(order_.size());
  for (std::size_t c = 0; c < out.columns.size(); ++c) {
    const Pose2& T = motion_[c];
    const double ct = std::cos(T.yaw), st = std::sin(T.yaw);
    for (std::uint32_t k = out.columns[c].begin; k < out.columns[c].end; ++k) {
      const hal::LidarPoint& p = in[order_[k]];
      const double xl = cos_pitch_ * p.x + sin_pitch_ * p.z;
      const double yl = p.y;
      const double zl = -sin_pitch_ * p.x + cos_pitch_ * p.z;
      const double bx = calib_.mount_x + xl, by = calib_.mount_y + yl;
      CloudPoint& q = out.points[k];
      q.x = static_cast<float>(T.x + ct * bx - st * by);
      q.y = static_cast<float>(T.y + st * bx + ct * by);
      q.z = static_cast<float>(calib_.mount_z + zl);
      q.range_xy = static_cast<float>(std::sqrt(xl * xl + yl * yl));
      q.z_sensor = static_cast<float>(zl);
      q.height = 0.0f;
      q.intensity = p.intensity;
      q.ring = p.ring;
      q.label = PointLabel::NonGround;
      q.vertical = false;
    }
  }
}

}  // namespace paddock::perception
