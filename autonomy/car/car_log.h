#pragma once
// the car's log, run.mcap, as the car binary writes it (and the simulator's
// run, which adds what was true: sim/runner/run_log.h). The file Foxglove
// opens and `paddock replay` reruns. It records what crossed the car's wires,
// byte for byte (the LiDAR's UDP packets, the CAN frames both ways), the
// object messages (the detector node's boxes: JSON, hal/json.h), and what
// the stack made of it in Foxglove's well-known schemas, with the files a
// reader needs (the scenario, track, LiDAR metadata, DBC) as attachments.
//
// Topics (log time = when the message crossed: the car's receive time, or the
// simulation's instant):
//   /lidar/packets   ouster.lidar_packet.legacy  one UDP payload each (no schema)
//   /can/rx, /can/tx socketcan.can_frame         struct can_frame, to / from the stack
//   /hal/detections  json paddock.CameraDetections  the detector node's boxes
//   /hal/cones       json paddock.ConeDetections    an object-level sensor's cones
//   /hal/state       json paddock.StateEstimate     an INS's state (slam = ground_truth)
//   /stack/command   json paddock.ActuatorCommand    the stack's command, each control cycle
//                    (the cycle's instant: a replay runs its cycles at these)
//   /tf              foxglove.FrameTransform     map -> base (the stack's estimate), base -> lidar
//   /stack/pose      foxglove.PoseInFrame        the base in the map, as estimated
//   /stack/map       foxglove.SceneUpdate        the stack's cone map (1 Hz)
//   /stack/path      foxglove.SceneUpdate        the trajectory it follows (when it changes, at most 2 Hz)
//   /lidar/points    foxglove.PointCloud         every kPointCloudEvery-th rotation, decoded from its packets
//   /camera/image    foxglove.CompressedImage    the camera's frames, JPEG
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "autonomy/common/serial_worker.h"
#include "autonomy/hal/messages.h"
#include "autonomy/hal/shared_frame.h"
#include "autonomy/hal/ouster.h"
#include "autonomy/log/mcap.h"
#include "autonomy/stack/stack.h"

namespace paddock::car {

class CarLog {
 public:
  // a point cloud every this many rotations (2 Hz at 10 Hz): the packets
  // hold every scan; the clouds are for looking at
  static constexpr int kPointCloudEvery = 5;

  struct File {
    std::string name, media_type, data;
  };
  // writes `path` (through path.tmp, renamed at close()); throws
  // std::runtime_error when it cannot. lidar: the LiDAR's metadata (its
  // packets become clouds) and layout (where it sits on the car);
  // pose_period: the estimate's poses at most this often. threaded: the
  // encoding (JSON, JPEG, the clouds' decode), compression and writing are
  // done on a thread of the log's own (a SerialWorker: in the order the
  // calls came, so the file's bytes are the same either way; a problem it
  // meets is thrown by a later cycle() or close()); false: all on the
  // caller's thread
  CarLog(const std::string& path, const std::vector<File>& attachments, const log::KeyValues& metadata,
         const std::optional<hal::ouster::SensorInfo>& lidar, const hal::LidarLayout& layout, TimeNs pose_period,
         bool threaded = true);
  // the file left unfinished (its .tmp) without close()
  ~CarLog();

  void lidar_packet(TimeNs at, const std::uint8_t* data, std::size_t size);
  // 16 bytes of struct can_frame, to the stack (the sensors) or from it (the command)
  void can_frame(TimeNs at, bool to_stack, const std::uint8_t* frame);
  // a message no wire carries (the others are logged as their bytes: nothing)
  void message(TimeNs at, const hal::SensorMessage& m);
  // a camera frame, as JPEG bytes, exposed at `stamp`
  void image(TimeNs at, TimeNs stamp, const std::vector<std::uint8_t>& jpeg);
  // the same from its pixels, encoded as JPEG of this quality (on the log's thread)
  void image(TimeNs at, const hal::CameraFrame& frame, int quality);
  // the same from a frame lent by its writer (hal/shared_frame.h): no copy,
  // the lease held until the log's thread has encoded it
  void image(TimeNs at, hal::FrameLease frame, int quality);
  // the control cycle at `at`: the command the stack sent, and what it made
  // of the world (its estimate, map and path); hands the cycle's messages
  // to the log's thread
  void cycle(TimeNs at, const hal::ActuatorCommand& command, const stack::Stack& stack);

  // a channel of the caller's own (the simulator's truth), and a message on it
  std::uint16_t channel(const std::string& topic, const std::string& schema, const std::string& encoding);
  void write(std::uint16_t channel, TimeNs at, const std::string& data);

  // finishes the file (summary, footer) and puts it in place
  void close();

 private:
  // these run on the log's thread (the caller's without one), and the
  // members below are that thread's, but for mounted_ and the next_ and
  // path_ marks: cycle() decides on the caller's thread what is due
  void write_now(std::uint16_t channel, TimeNs at, const std::uint8_t* data, std::size_t size);
  void write_now(std::uint16_t channel, TimeNs at, const std::string& data);
  void decode(TimeNs at, const std::uint8_t* data, std::size_t size);

  std::unique_ptr<log::McapWriter> mcap_;
  std::unique_ptr<hal::ouster::Decoder> decoder_;  // the clouds, from the logged packets
  hal::LidarLayout layout_;
  TimeNs pose_period_ = 0;
  std::vector<std::uint32_t> sequence_;           // per channel
  std::map<std::string, std::uint16_t> schemas_;  // by name
  std::uint16_t packets_ = 0, can_rx_ = 0, can_tx_ = 0, detections_ = 0, cones_ = 0, state_ = 0, tf_ = 0,
                pose_ = 0, command_ = 0, map_ = 0, path_ = 0, points_ = 0, image_ = 0;
  bool mounted_ = false;  // base -> lidar written
  std::vector<float> xyzi_;  // a cloud's points, kept for the next
  std::string text_;         // a message's JSON text, kept for the next
  std::optional<TimeNs> next_pose_, next_map_, next_path_;
  const void* path_of_ = nullptr;  // the trajectory last logged (its points' storage)
  std::size_t path_points_ = 0;
  double path_length_ = -1.0;
  // last: destroyed first, running what is posted before the writer goes
  std::unique_ptr<SerialWorker> worker_;
};

}  // namespace paddock::car
