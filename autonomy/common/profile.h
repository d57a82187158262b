#pragma once
// where a run's wall time goes (`paddock run --profile`): the time of each
// stage, measured where its work is done. A stage entered inside another is
// charged its own time alone (exclusive time), so the stages and `other` (the
// time inside no stage) add up to the time between start() and stop().
// Nothing is timed through a null Profile pointer (StageScope).
//
// The clock: the CPU's time-stamp counter (x86-64; 10 ns a read here
// against steady_clock's 24: the loop enters 3 stages a physics step,
// physics, scoring and logging, and the reads were a tenth of a run on the
// true state when it entered 6), its rate measured against
// steady_clock between start() and stop(), so the stages add up to
// steady_clock's time exactly (the counter runs at a constant rate on
// CPUs that say constant_tsc, every x86-64 of the last decade); elsewhere,
// or given a clock of its own (the tests'), that clock. Given a
// counter of the thread's allocations, each stage is charged the allocations
// made inside it too, the same way.
#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string_view>

namespace paddock {

enum class Stage : std::uint8_t {
  Other,         // inside no stage: the loop, the odometry sensors, the VCU, the event's sample
  Physics,       // the vehicle model, the cones' contacts, the timing gates
  Lidar,         // the LiDAR's ray cast (with the scene's update) and its packets
  Camera,        // the camera's render and the detector node's boxes
  Perception,    // the stack's perception: ground, clusters, colour, fusion
  Localisation,  // velocity estimation, SLAM (FastSLAM and the graph, or LIO), the cone map
  Planning,      // the centreline search, smoothing, splines, the velocity profile
  Control,       // the lateral and longitudinal controllers
  Logging,       // the run's log rows and its MCAP log (--log)
  Scoring,       // the perception, SLAM and snapshot observers (the run's figures)
};
inline constexpr std::size_t kStageCount = 10;

// "physics", "lidar", ...: the summary's and the table's names
std::string_view stage_name(Stage s);

class Profile {
 public:
  using Clock = std::chrono::steady_clock;
  using Now = Clock::time_point (*)();
  using Count = std::uint64_t (*)();
  // now: a clock of its own (null: the CPU's counter, see above)
  explicit Profile(Now now = nullptr, Count count = nullptr) : now_(now), count_(count) {}

  void start();
  void stop();
  void enter(Stage s);
  void leave();

  double seconds(Stage s) const { return static_cast<double>(ticks_[static_cast<std::size_t>(s)]) * seconds_per_tick(); }
  std::uint64_t entries(Stage s) const { return entries_[static_cast<std::size_t>(s)]; }
  double total() const;  // s, every stage and other
  // allocations made in the stage (0 without a counter)
  bool counts_allocations() const { return count_ != nullptr; }
  std::uint64_t allocations(Stage s) const { return allocations_[static_cast<std::size_t>(s)]; }
  std::uint64_t total_allocations() const;

 private:
  void charge();  // the time since the last mark, to the innermost stage
  std::uint64_t tick() const;  // the counter (ns of now_ when given)
  Clock::time_point clock() const { return now_ ? now_() : Clock::now(); }
  // the counter's period: measured from start() to stop() (to now while running)
  double seconds_per_tick() const;
  static constexpr int kDepth = 16;  // deeper scopes are charged to the 16th

  Now now_;
  Count count_;
  bool running_ = false;
  std::uint64_t mark_ = 0;
  std::uint64_t count_mark_ = 0;
  // the calibration: the counter and the clock at start() and stop()
  std::uint64_t tick0_ = 0, tick1_ = 0;
  Clock::time_point clock0_{}, clock1_{};
  std::array<std::uint64_t, kStageCount> ticks_{};
  std::array<std::uint64_t, kStageCount> allocations_{};
  std::array<std::uint64_t, kStageCount> entries_{};
  std::array<Stage, kDepth> open_{};  // open_[0]: Other
  int depth_ = 0;                     // open stages (may exceed kDepth)
};

// a stage for the scope's lifetime (nothing when profile is null)
class StageScope {
 public:
  StageScope(Profile* profile, Stage s) : profile_(profile) {
    if (profile_) profile_->enter(s);
  }
  ~StageScope() {
    if (profile_) profile_->leave();
  }
  StageScope(const StageScope&) = delete;
  StageScope& operator=(const StageScope&) = delete;

 private:
  Profile* profile_;
};

// f() timed as stage s, its result returned as f returns it
template <class F>
decltype(auto) timed(Profile* profile, Stage s, F&& f) {
  const StageScope scope(profile, s);
  return f();
}

}  // namespace paddock
