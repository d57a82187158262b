#pragma once
// where a run's wall time goes (`paddock run --profile`): the time of each
// stage, measured where its work is done. A stage entered inside another is
// charged its own time alone (exclusive time), so the stages and `other` (the
// time inside no stage) add up to the time between start() and stop().
// Nothing is timed through a null Profile pointer (StageScope). Given a
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
  explicit Profile(Now now = &Clock::now, Count count = nullptr) : now_(now), count_(count) {}

  void start();
  void stop();
  void enter(Stage s);
  void leave();

  double seconds(Stage s) const { return seconds_[static_cast<std::size_t>(s)]; }
  std::uint64_t entries(Stage s) const { return entries_[static_cast<std::size_t>(s)]; }
  double total() const;  // s, every stage and other
  // allocations made in the stage (0 without a counter)
  bool counts_allocations() const { return count_ != nullptr; }
  std::uint64_t allocations(Stage s) const { return allocations_[static_cast<std::size_t>(s)]; }
  std::uint64_t total_allocations() const;

 private:
  void charge();  // the time since the last mark, to the innermost stage
  static constexpr int kDepth = 16;  // deeper scopes are charged to the 16th

  Now now_;
  Count count_;
  bool running_ = false;
  Clock::time_point mark_{};
  std::uint64_t count_mark_ = 0;
  std::array<double, kStageCount> seconds_{};
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
