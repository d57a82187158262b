#include "sim/runner/run_log.h"

#include "autonomy/hal/image.h"
#include "autonomy/log/foxglove.h"
#include "sim/runner/files.h"
#include "sim/runner/scenario.h"
#include "sim/runner/simulation.h"
#include "sim/vehicle/vehicle.h"

namespace paddock::runner {

namespace fg = log::foxglove;

std::vector<car::CarLog::File> log_attachments(const Scenario& sc) {
  std::vector<car::CarLog::File> files;
  if (sc.lidar_info) files.push_back({"lidar_metadata.json", "application/json", hal::ouster::to_json(*sc.lidar_info)});
  files.push_back({"car.dbc", "text/plain", sc.dbc_text});
  files.push_back({"track.csv", "text/csv", read_file(sc.track_path)});
  files.push_back({"scenario.ini", "text/plain", resolved_ini(sc)});
  return files;
}

RunLog::RunLog(const std::string& path, const Scenario& sc) {
  if (sc.hal.transport == Transport::Memory)
    throw UserError(sc.source + ": --log records the car's wires: it needs [hal] transport = wire or udp (include = sensors/ouster.ini names the sensors' files; scenarios/fsg_2023_autocross_wire.ini is an example)");
  const std::vector<car::CarLog::File> files = log_attachments(sc);
  const char* transport = sc.hal.transport == Transport::Udp ? "udp" : "wire";
  try {
    log_ = std::make_unique<car::CarLog>(path, files,
                                         log::KeyValues{{"scenario", sc.source},
                                                        {"seed", std::to_string(sc.scenario.seed)},
                                                        {"transport", transport}},
                                         sc.lidar_info, sc.lidar, kNsPerSecond / sc.sim.log_rate);
  } catch (const std::runtime_error& e) {
    throw UserError(e.what());
  }
  truth_pose_ = log_->channel("/truth/pose", fg::pose_in_frame_schema(), "json");
  truth_cones_ = log_->channel("/truth/cones", fg::scene_update_schema(), "json");
  log_every_ = std::max(1, sc.sim.physics_rate / sc.sim.log_rate);
}

RunLog::~RunLog() = default;

void RunLog::lidar_packet(TimeNs at, const std::uint8_t* data, std::size_t size) { log_->lidar_packet(at, data, size); }

void RunLog::can_frame(TimeNs at, bool to_stack, const std::uint8_t* frame) { log_->can_frame(at, to_stack, frame); }

void RunLog::message(TimeNs at, const hal::SensorMessage& m) { log_->message(at, m); }

void RunLog::observe(const SimModel& model, SimState& s) {
  const TimeNs at = s.now;
  // the stack's command as it sent it (/can/tx has it as the wire carried
  // it) and what it made of the world; with transport = udp the car binary
  // logs them
  if (s.controlled && !s.hal.remote() && s.hal.sent()) log_->cycle(at, *s.hal.sent(), s.stack);
  // the camera's frames, as the car logs them (painted from now on)
  if (s.raw) s.raw->set_pixels(true);
  if (const hal::CameraFrame* f = s.raw ? s.raw->camera_frame() : nullptr; f && f->stamp != last_image_) {
    last_image_ = f->stamp;
    log_->image(at, s.raw->lend_camera_frame(), kJpegQuality);
  }
  // what was true: the pose at the log rate, the cones once a second
  if (s.k % log_every_ == 0) {
    const Pose2 truth = vehicle::base_pose(model.scenario.vehicle, s.car);
    fg::pose_in_frame(at, "map", truth.x, truth.y, truth.yaw, text_);
    log_->write(truth_pose_, at, text_);
  }
  if (at >= next_truth_cones_) {
    next_truth_cones_ = at + kNsPerSecond;
    truth_cones_of_.resize(static_cast<std::size_t>(s.cones.cone_count()));
    for (int i = 0; i < s.cones.cone_count(); ++i)
      truth_cones_of_[static_cast<std::size_t>(i)] = {s.cones.cone_position(i), s.cones.cone(i).color};
    fg::cones_update(truth_cones_of_, at, "truth_cones", text_);
    log_->write(truth_cones_, at, text_);
  }
}

void RunLog::close() { log_->close(); }

}  // namespace paddock::runner
