#include "autonomy/car/car_log.h"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <variant>

#include "autonomy/hal/car_can.h"
#include "autonomy/hal/image.h"
#include "autonomy/hal/json.h"
#include "autonomy/log/foxglove.h"

namespace paddock::car {

namespace fg = log::foxglove;
using nlohmann::json;

CarLog::CarLog(const std::string& path, const std::vector<File>& attachments, const log::KeyValues& metadata,
               const std::optional<hal::ouster::SensorInfo>& lidar, const hal::LidarLayout& layout,
               TimeNs pose_period, bool threaded)
    // up to 128 control cycles' messages waiting (~1.3 s of a run, ~10 MB):
    // a 4 MB chunk's compression on the log's thread holds it up ~10 ms,
    // and with 16 the loop waited for it (a logged autocross on 2 cores
    // +16 % against +11 %)
    : layout_(layout), pose_period_(pose_period), worker_(std::make_unique<SerialWorker>(threaded, 128)) {
  log::McapWriterOptions o;
  o.profile = "";
  o.library = "paddock";
  o.background = false;  // the chunks are compressed where everything else is: the worker's thread
  try {
    mcap_ = std::make_unique<log::McapWriter>(std::make_unique<log::FileSink>(path), o);
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": cannot write the log: " + e.what());
  }
  for (const File& f : attachments)
    mcap_->write_attachment({0, 0, f.name, f.media_type, std::vector<std::uint8_t>(f.data.begin(), f.data.end())});
  mcap_->write_metadata("paddock", metadata);
  if (lidar) {
    decoder_ = std::make_unique<hal::ouster::Decoder>(*lidar, layout);
    decoder_->set_scan_every(kPointCloudEvery);  // the other rotations' points are not needed
  }

  packets_ = channel("/lidar/packets", "", "ouster.lidar_packet.legacy");
  can_rx_ = channel("/can/rx", "", "socketcan.can_frame");
  can_tx_ = channel("/can/tx", "", "socketcan.can_frame");
  const json stamp = fg::integer_schema(), number = fg::number_schema();
  const json box = fg::object_of({{"x_min", number}, {"y_min", number}, {"x_max", number}, {"y_max", number},
                                  {"color", fg::integer_schema()}, {"confidence", number}});
  detections_ = channel("/hal/detections",
                        fg::object_schema("paddock.CameraDetections", {{"type", fg::string_schema()},
                                                                       {"stamp", stamp},
                                                                       {"width", fg::integer_schema()},
                                                                       {"height", fg::integer_schema()},
                                                                       {"boxes", fg::array_schema(box)}}),
                        "json");
  const json cone = fg::object_of({{"x", number}, {"y", number}, {"color", fg::integer_schema()},
                                   {"colour_from_camera", fg::boolean_schema()}});
  cones_ = channel("/hal/cones",
                   fg::object_schema("paddock.ConeDetections", {{"type", fg::string_schema()},
                                                                {"stamp", stamp},
                                                                {"cones", fg::array_schema(cone)},
                                                                {"free_range", fg::array_schema(number)}}),
                   "json");
  state_ = channel("/hal/state",
                   fg::object_schema("paddock.StateEstimate", {{"type", fg::string_schema()}, {"stamp", stamp},
                                                               {"x", number}, {"y", number}, {"yaw", number},
                                                               {"vx", number}, {"vy", number}, {"yaw_rate", number}}),
                   "json");
  command_ = channel("/stack/command",
                     fg::object_schema("paddock.ActuatorCommand", {{"stamp", stamp},
                                                                   {"steering_angle", number},
                                                                   {"throttle", number},
                                                                   {"brake", number},
                                                                   {"yaw_moment", number},
                                                                   {"as_state", fg::string_schema()}}),
                     "json");
  tf_ = channel("/tf", fg::frame_transform_schema(), "json");
  pose_ = channel("/stack/pose", fg::pose_in_frame_schema(), "json");
  map_ = channel("/stack/map", fg::scene_update_schema(), "json");
  path_ = channel("/stack/path", fg::scene_update_schema(), "json");
  points_ = channel("/lidar/points", fg::point_cloud_schema(), "json");
  image_ = channel("/camera/image", fg::compressed_image_schema(), "json");
}

CarLog::~CarLog() = default;

std::uint16_t CarLog::channel(const std::string& topic, const std::string& schema, const std::string& encoding) {
  worker_->drain();  // the writer is the caller's for a moment
  // one Schema record per schema, however many channels use it
  std::uint16_t schema_id = 0;
  if (!schema.empty()) {
    const std::string name = json::parse(schema).value("title", topic);
    const auto it = schemas_.find(name);
    schema_id = it != schemas_.end() ? it->second : (schemas_[name] = mcap_->add_schema(name, "jsonschema", schema));
  }
  const std::uint16_t id = mcap_->add_channel(schema_id, topic, encoding, {});
  if (sequence_.size() <= id) sequence_.resize(id + 1u, 0);
  return id;
}

void CarLog::write_now(std::uint16_t ch, TimeNs at, const std::uint8_t* data, std::size_t size) {
  const auto t = static_cast<std::uint64_t>(std::max<TimeNs>(at, 0));
  mcap_->write(ch, sequence_[ch]++, t, t, data, size);
}

void CarLog::write_now(std::uint16_t ch, TimeNs at, const std::string& data) {
  write_now(ch, at, reinterpret_cast<const std::uint8_t*>(data.data()), data.size());
}

void CarLog::write(std::uint16_t ch, TimeNs at, const std::string& data) {
  worker_->post([this, ch, at, data] { write_now(ch, at, data); });
}

void CarLog::decode(TimeNs at, const std::uint8_t* data, std::size_t size) {
  decoder_->push(data, size);
  // every kPointCloudEvery-th rotation (the decoder scans no other)
  while (std::optional<hal::LidarScan> scan = decoder_->pop()) {
    // in the sensor frame as it stood (raw: not deskewed)
    xyzi_.clear();
    for (const hal::LidarPoint& p : scan->points) xyzi_.insert(xyzi_.end(), {p.x, p.y, p.z, p.intensity});
    fg::point_cloud(scan->end, "lidar", xyzi_.data(), scan->points.size(), text_);
    write_now(points_, at, text_);
  }
}

void CarLog::lidar_packet(TimeNs at, const std::uint8_t* data, std::size_t size) {
  worker_->post([this, at, packet = std::vector<std::uint8_t>(data, data + size)] {
    write_now(packets_, at, packet.data(), packet.size());
    if (decoder_) decode(at, packet.data(), packet.size());
  });
}

void CarLog::can_frame(TimeNs at, bool to_stack, const std::uint8_t* frame) {
  std::array<std::uint8_t, hal::kSocketCanFrameSize> bytes;
  std::copy(frame, frame + bytes.size(), bytes.begin());
  worker_->post([this, at, ch = to_stack ? can_rx_ : can_tx_, bytes] { write_now(ch, at, bytes.data(), bytes.size()); });
}

void CarLog::message(TimeNs at, const hal::SensorMessage& m) {
  worker_->post([this, at, m] {
    const std::optional<std::string> j = hal::to_json(m);
    if (!j) return;  // a wire carries it: logged as its bytes
    const std::uint16_t ch = std::holds_alternative<hal::CameraDetections>(m) ? detections_
                             : std::holds_alternative<hal::ConeDetections>(m) ? cones_
                                                                              : state_;
    write_now(ch, at, *j);
  });
}

void CarLog::image(TimeNs at, TimeNs stamp, const std::vector<std::uint8_t>& jpeg) {
  worker_->post([this, at, stamp, jpeg] {
    fg::compressed_image(stamp, "camera", jpeg.data(), jpeg.size(), "jpeg", text_);
    write_now(image_, at, text_);
  });
}

void CarLog::image(TimeNs at, const hal::CameraFrame& frame, int quality) {
  // a copy, lent to the log's thread as a writer's frame is
  auto copy = std::make_shared<hal::SharedFrame>();
  copy->frame = frame;
  image(at, hal::FrameLease(std::move(copy)), quality);
}

void CarLog::image(TimeNs at, hal::FrameLease frame, int quality) {
  worker_->post([this, at, frame = std::move(frame), quality]() mutable {
    const std::vector<std::uint8_t> jpeg = hal::encode_jpeg(*frame, quality);
    fg::compressed_image(frame->stamp, "camera", jpeg.data(), jpeg.size(), "jpeg", text_);
    write_now(image_, at, text_);
    frame = hal::FrameLease();  // let go of it as soon as it is encoded
  });
}

void CarLog::cycle(TimeNs at, const hal::ActuatorCommand& c, const stack::Stack& stack) {
  // what is due is decided here, from the stack as it is now; the messages
  // are made on the log's thread from copies
  const bool mount = !mounted_;
  mounted_ = true;
  std::optional<hal::StateEstimate> pose;
  const std::optional<hal::StateEstimate>& e = stack.estimate();
  if (e && (!next_pose_ || at >= *next_pose_)) {
    next_pose_ = at + pose_period_;
    pose = e;
  }
  std::optional<std::vector<Cone>> map;
  if (!next_map_ || at >= *next_map_) {
    next_map_ = at + kNsPerSecond;
    map = stack.cone_map().cones();
  }
  // the trajectory when it changed, at most twice a second
  std::optional<std::vector<Vec2>> path;
  const Trajectory& tr = stack.trajectory();
  const bool changed = tr.points.data() != path_of_ || tr.points.size() != path_points_ || tr.length != path_length_;
  if (changed && (!next_path_ || at >= *next_path_) && !tr.empty()) {
    next_path_ = at + kNsPerSecond / 2;
    path_of_ = tr.points.data();
    path_points_ = tr.points.size();
    path_length_ = tr.length;
    path.emplace();
    path->reserve(tr.points.size());
    for (const TrajectoryPoint& p : tr.points) path->push_back(p.position());
  }
  worker_->post([this, at, c, mount, pose, map = std::move(map), path = std::move(path), closed = tr.closed] {
    if (mount) {
      // where the LiDAR sits on the car
      fg::transform(at, "base", "lidar", layout_.mount_x, layout_.mount_y, layout_.mount_z, 0.0, layout_.mount_pitch,
                    text_);
      write_now(tf_, at, text_);
    }
    // the command (its keys in the order json::dump() sorts them)
    fg::JsonWriter(text_)
        .begin_object()
        .key("as_state").string(hal::to_string(c.as_state))
        .key("brake").number(c.brake)
        .key("stamp").integer(c.stamp)
        .key("steering_angle").number(c.steering_angle)
        .key("throttle").number(c.throttle)
        .key("yaw_moment").number(c.yaw_moment)
        .end_object();
    write_now(command_, at, text_);
    if (pose) {
      fg::pose_in_frame(pose->stamp, "map", pose->pose.x, pose->pose.y, pose->pose.yaw, text_);
      write_now(pose_, at, text_);
      fg::transform(pose->stamp, "map", "base", pose->pose.x, pose->pose.y, 0.0, pose->pose.yaw, 0.0, text_);
      write_now(tf_, at, text_);
    }
    if (map) {
      fg::cones_update(*map, at, "stack_map", text_);
      write_now(map_, at, text_);
    }
    if (path) write_now(path_, at, fg::line_update(*path, closed, at, "path").dump());
  });
  worker_->flush();  // the cycle's messages to the log's thread: the threads meet once a cycle
}

void CarLog::close() {
  worker_->drain();
  mcap_->close();
}

}  // namespace paddock::car
