#include "autonomy/common/profile.h"

#include <algorithm>

#if defined(__x86_64__)
#include <x86intrin.h>
#endif

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

std::uint64_t Profile::tick() const {
  if (now_ != nullptr) return static_cast<std::uint64_t>(std::chrono::nanoseconds(now_().time_since_epoch()).count());
#if defined(__x86_64__)
  return __rdtsc();
#else
  return static_cast<std::uint64_t>(std::chrono::nanoseconds(Clock::now().time_since_epoch()).count());
#endif
}

double Profile::seconds_per_tick() const {
  if (now_ != nullptr) return 1e-9;  // the ticks are the clock's ns
#if defined(__x86_64__)
  const std::uint64_t t1 = running_ ? tick() : tick1_;
  const Clock::time_point c1 = running_ ? clock() : clock1_;
  if (t1 <= tick0_) return 0.0;  // never started
  return std::chrono::duration<double>(c1 - clock0_).count() / static_cast<double>(t1 - tick0_);
#else
  return 1e-9;
#endif
}

void Profile::start() {
  if (running_) return;
  running_ = true;
  if (count_ != nullptr) count_mark_ = count_();
  clock0_ = clock();
  mark_ = tick0_ = tick();
}

void Profile::stop() {
  if (!running_) return;
  charge();
  tick1_ = mark_;
  clock1_ = clock();
  running_ = false;
}

void Profile::charge() {
  if (!running_) return;  // not started (or stopped): no clock read at all
  const std::uint64_t t = tick();
  const Stage s = depth_ == 0 ? Stage::Other : open_[static_cast<std::size_t>(std::min(depth_, kDepth) - 1)];
  ticks_[static_cast<std::size_t>(s)] += t - mark_;
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
  std::uint64_t t = 0;
  for (std::uint64_t n : ticks_) t += n;
  return static_cast<double>(t) * seconds_per_tick();
}

std::uint64_t Profile::total_allocations() const {
  std::uint64_t n = 0;
  for (std::uint64_t a : allocations_) n += a;
  return n;
}

}  // namespace paddock
