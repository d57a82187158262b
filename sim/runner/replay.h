#pragma once
// `paddock replay run.mcap`: the stack rerun on a run's log, without the
// simulator. The recorded wire messages (the LiDAR's packets, the CAN frames
// to the stack) go through the car's decoders, and the messages that crossed
// the HAL as structs (the detector node's boxes) are read back, each handed
// to the stack at the control cycle it reached it in the live run; the stack
// is the car binary's (car::CarNode: its decoders and watchdogs), built
// from the log's own scenario (an attachment, with the track, the
// LiDAR's metadata and the DBC). Unchanged, it gives the live run's commands
// to the bit; with --set it reruns a changed stack on the same log and says
// where and how much its commands differ (the way a team debugs a real
// car's log).
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "autonomy/common/profile.h"

namespace paddock::runner {

struct ReplayOptions {
  std::vector<std::string> overrides;  // --set section.key=value (the stack's keys)
  std::optional<double> from;          // s: the stack starts here (fresh), the log before it unread
  std::optional<double> until;         // s: stops here
  bool profile = false;                // --profile: where the wall time went, by stage
  // --threads N: 2 or more reads the log, and runs the LiDAR pipeline on
  // its scans, on a second thread (car/read_ahead.h: the same result)
  int threads = 1;
};

struct ReplayResult {
  long cycles = 0;             // control cycles replayed
  long compared = 0;           // of them with a logged command to compare
  long identical = 0;          // whose command equals the logged one to the bit
  std::optional<double> first_difference;  // s, the first cycle whose command differs
  double max_steering_difference = 0.0;    // rad
  double max_throttle_difference = 0.0;    // -
  double max_brake_difference = 0.0;       // -
  long as_state_differences = 0;
  std::string final_as_state;              // the replayed stack's at the end
  std::string watchdog_fault;              // why a watchdog of the car fired, if one did
  long lidar_scans = 0, can_frames = 0, struct_messages = 0;
  // --threads 2: the scans whose LiDAR pipeline the second thread ran (and
  // the stack took), and those the stack ran itself
  long scans_ahead = 0, scans_not_ahead = 0;
  double log_time = 0.0;   // s of log replayed
  double wall_time = 0.0;  // s
  // by stage (--profile): reading the log as logging, the LiDAR's decoding
  // as lidar, the stack's own stages as in a run
  std::optional<Profile> profile;
};

// replays `path`; throws UserError for a file that is no paddock log (or a
// damaged one: log::McapError's offset and reason)
ReplayResult replay(const std::string& path, const ReplayOptions& options);

// the printed report
std::string replay_text(const std::string& path, const ReplayResult& r);

}  // namespace paddock::runner
