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

MotionCorrector::MotionCorrector(const LidarCalibration& calibration) : calib_(calibration) {
  params::require_valid(calib_, "LidarCalibration");
  cos_pitch_ = std::cos(calib_.mount_pitch);
  sin_pitch_ = std::sin(calib_.mount_pitch);
}

void MotionCorrector::correct(const hal::LidarScan& scan, const Odometry* odometry, Cloud& out) {
  out.stamp = scan.end;
  out.corrected = false;
  out.points_in = scan.points.size();
  out.invalid = 0;
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
    times_.clear();
    for (const CloudColumn& col : out.columns) times_.push_back(col.t);
    const bool covered = odometry->relative(scan.end, times_.data(), times_.size(), motion_.data());
    out.corrected = covered;
    if (!covered) std::fill(motion_.begin(), motion_.end(), Pose2{});
  }

  // lidar -> levelled sensor -> base at the column's time -> base at the end
  // (every field of every point is written below: the points of the last
  // scan are overwritten, not cleared and value-initialised first)
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
