#pragma once
// a run's log, `paddock run ... --log`: DIR/run.mcap, the file Foxglove
// opens. It records what crossed the car's wires, byte for byte (the LiDAR's
// UDP packets, the CAN frames both ways), what crossed the HAL as structs
// (the detector node's boxes: JSON), and what the stack made of it and what
// was true, in Foxglove's well-known JSON schemas (foxglove.FrameTransform,
// PoseInFrame, SceneUpdate, PointCloud), so a team sees the car, the scan,
// the cones, the map and the path in 3D. The metadata file, the DBC and the
// resolved scenario travel in the file as attachments: a log is complete.
//
// Topics (log time = the simulation's instant the message crossed):
//   /lidar/packets   ouster.lidar_packet.legacy  one UDP payload each (no schema)
//   /can/rx, /can/tx socketcan.can_frame         struct can_frame, to / from the stack
//   /hal/detections  json paddock.CameraDetections  the detector node's boxes
//   /hal/cones       json paddock.ConeDetections    an object-level sensor's cones
//   /hal/state       json paddock.StateEstimate     the true state (slam = ground_truth)
//   /tf              foxglove.FrameTransform     map -> base (the stack's estimate), base -> lidar
//   /stack/pose, /truth/pose  foxglove.PoseInFrame  the base in the map: estimated, true
//   /stack/command   json paddock.ActuatorCommand    the stack's command, each control cycle
//   /stack/map       foxglove.SceneUpdate        the stack's cone map (1 Hz)
//   /stack/path      foxglove.SceneUpdate        the trajectory it follows (when it changes, at most 2 Hz)
//   /truth/cones     foxglove.SceneUpdate        the cones as they stand (1 Hz)
//   /lidar/points    foxglove.PointCloud         every kPointCloudEvery-th rotation, decoded from its packets
// A log needs the wire: [hal] transport = wire.
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "autonomy/hal/ouster.h"
#include "autonomy/log/mcap.h"
#include "sim/runner/observers.h"
#include "sim/runner/scenario.h"
#include "sim/runner/wire.h"

namespace paddock::runner {

class RunLog final : public Observer, public WireTap {
 public:
  // a point cloud every this many rotations (2 Hz at 10 Hz): the packets
  // hold every scan; the clouds are for looking at
  static constexpr int kPointCloudEvery = 5;

  // writes `path` (through path.tmp, renamed at close()); throws UserError
  // when the scenario does not run on the wire or the file cannot be made
  RunLog(const std::string& path, const Scenario& scenario);
  ~RunLog() override;

  void observe(const SimModel& model, SimState& state) override;
  void lidar_packet(TimeNs at, const std::uint8_t* data, std::size_t size) override;
  void can_frame(TimeNs at, bool to_stack, const std::uint8_t* frame) override;
  void message(TimeNs at, const hal::SensorMessage& m) override;

  // finishes the file (summary, footer) and puts it in place
  void close();

 private:
  std::uint16_t channel(const std::string& topic, const std::string& schema, const std::string& encoding);
  void write(std::uint16_t channel, TimeNs at, const std::string& data);
  void write(std::uint16_t channel, TimeNs at, const std::uint8_t* data, std::size_t size);

  std::unique_ptr<log::McapWriter> mcap_;
  std::optional<hal::ouster::SensorInfo> info_;
  std::unique_ptr<hal::ouster::Decoder> decoder_;  // the clouds, from the logged packets
  std::vector<std::uint32_t> sequence_;            // per channel
  std::map<std::string, std::uint16_t> schemas_;   // by name
  std::uint16_t packets_ = 0, can_rx_ = 0, can_tx_ = 0, detections_ = 0, cones_ = 0, state_ = 0, tf_ = 0,
                pose_ = 0, truth_pose_ = 0, command_ = 0, map_ = 0, path_ = 0, truth_cones_ = 0, points_ = 0;
  bool started_ = false;
  long rotations_ = 0;
  TimeNs next_map_ = 0, next_path_ = 0;
  const void* path_of_ = nullptr;  // the trajectory last logged (its points' storage)
  std::size_t path_points_ = 0;
  double path_length_ = -1.0;
  int log_every_ = 10;  // physics steps between pose samples
};

}  // namespace paddock::runner
