#pragma once
// a run's log, `paddock run ... --log`: DIR/run.mcap, the file Foxglove opens
// and `paddock replay` reruns. The car's log (autonomy/car/car_log.h: the
// wires' bytes, the object messages, the stack's command, estimate, map and
// path in Foxglove's schemas, the files a reader needs as attachments), and
// what was true:
//   /truth/pose      foxglove.PoseInFrame        the base in the map (log rate)
//   /truth/cones     foxglove.SceneUpdate        the cones as they stand (1 Hz)
// A log needs the wire: [hal] transport = wire, or udp (then the car binary
// logs the stack's side: paddock car ... --log).
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "autonomy/car/car_log.h"
#include "sim/runner/observers.h"
#include "sim/runner/scenario.h"
#include "sim/runner/wire.h"

namespace paddock::runner {

// what a log carries for its reader (paddock replay): the LiDAR's metadata,
// the DBC, the track and the resolved scenario
std::vector<car::CarLog::File> log_attachments(const Scenario& scenario);

class RunLog final : public Observer, public WireTap {
 public:
  // the camera's frames as JPEG of this quality
  static constexpr int kJpegQuality = 85;

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
  std::unique_ptr<car::CarLog> log_;
  std::uint16_t truth_pose_ = 0, truth_cones_ = 0;
  TimeNs next_truth_cones_ = 0;
  TimeNs last_image_ = -1;  // the camera frame last logged
  int log_every_ = 10;  // physics steps between true poses
  std::vector<Cone> truth_cones_of_;  // the cones as they stand, kept for the next
  std::string text_;                  // a message's JSON text, kept for the next
};

}  // namespace paddock::runner
