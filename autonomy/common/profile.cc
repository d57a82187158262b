#include "autonomy/common/profile.h"

#include <algorithm>

namespace paddock {

std::string_view stage_name(Stage s) {
  switch (s) {
    case Stage::Other: return "other";
    case Stage::Physics: return "physics";
    case Stage::Lidar: return "lidar";
    case Stage::Camera: return "camera";
    case Stage::Perception: return "perception";
    case Stage::Localisation: return "localisation";
    case Stage::Planning: return "planning";
    case Stage::Control: return "control";
    case Stage::Logging: return "logging";
    case Stage::Scoring: return "scoring";
  }
  return "?";
}

void Profile::start() {
  if (running_) return;
  running_ = true;
  if (count_ != nullptr) count_mark_ = count_();
  mark_ = now_();
}

void Profile::stop() {
  if (!running_) return;
  charge();
  running_ = false;
}

void Profile::charge() {
  if (!running_) return;  // not started (or stopped): no clock read at all
  const Clock::time_point t = now_();
  const Stage s = depth_ == 0 ? Stage::Other : open_[static_cast<std::size_t>(std::min(depth_, kDepth) - 1)];
  seconds_[static_cast<std::size_t>(s)] += std::chrono::duration<double>(t - mark_).count();
  mark_ = t;
  if (count_ != nullptr) {
    const std::uint64_t n = count_();
    allocations_[static_cast<std::size_t>(s)] += n - count_mark_;
    count_mark_ = n;
  }
}

void Profile::enter(Stage s) {
  charge();
  if (depth_ < kDepth) open_[static_cast<std::size_t>(depth_)] = s;
  ++depth_;
  ++entries_[static_cast<std::size_t>(s)];
}

void Profile::leave() {
  if (depth_ == 0) return;
  charge();
  --depth_;
}

double Profile::total() const {
  double t = 0.0;
  for (double s : seconds_) t += s;
  return t;
}

std::uint64_t Profile::total_allocations() const {
  std::uint64_t n = 0;
  for (std::uint64_t a : allocations_) n += a;
  return n;
}

}  // namespace paddock
