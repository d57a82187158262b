#include "autonomy/car/car_log.h"

#include <stdexcept>
#include <variant>

#include "autonomy/hal/car_can.h"
#include "autonomy/hal/json.h"
#include "autonomy/log/foxglove.h"

namespace paddock::car {

namespace fg = log::foxglove;
using nlohmann::json;

CarLog::CarLog(const std::string& path, const std::vector<File>& attachments, const log::KeyValues& metadata,
               const std::optional<hal::ouster::SensorInfo>& lidar, const hal::LidarLayout& layout,
               TimeNs pose_period)
    : layout_(layout), pose_period_(pose_period) {
  log::McapWriterOptions o;
  o.profile = "";
  o.library = "paddock";
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

void CarLog::write(std::uint16_t ch, TimeNs at, const std::uint8_t* data, std::size_t size) {
  const auto t = static_cast<std::uint64_t>(std::max<TimeNs>(at, 0));
  mcap_->write(ch, sequence_[ch]++, t, t, data, size);
}

void CarLog::write(std::uint16_t ch, TimeNs at, const std::string& data) {
  write(ch, at, reinterpret_cast<const std::uint8_t*>(data.data()), data.size());
}

void CarLog::lidar_packet(TimeNs at, const std::uint8_t* data, std::size_t size) {
  write(packets_, at, data, size);
  if (!decoder_) return;
  decoder_->push(data, size);
  // every kPointCloudEvery-th rotation (the decoder scans no other)
  while (std::optional<hal::LidarScan> scan = decoder_->pop()) {
    // in the sensor frame as it stood (raw: not deskewed)
    xyzi_.clear();
    for (const hal::LidarPoint& p : scan->points) xyzi_.insert(xyzi_.end(), {p.x, p.y, p.z, p.intensity});
    fg::point_cloud(scan->end, "lidar", xyzi_.data(), scan->points.size(), text_);
    write(points_, at, text_);
  }
}

void CarLog::can_frame(TimeNs at, bool to_stack, const std::uint8_t* frame) {
  write(to_stack ? can_rx_ : can_tx_, at, frame, hal::kSocketCanFrameSize);
}

void CarLog::message(TimeNs at, const hal::SensorMessage& m) {
  const std::optional<std::string> j = hal::to_json(m);
  if (!j) return;  // a wire carries it: logged as its bytes
  const std::uint16_t ch = std::holds_alternative<hal::CameraDetections>(m) ? detections_
                           : std::holds_alternative<hal::ConeDetections>(m) ? cones_
                                                                            : state_;
  write(ch, at, *j);
}

void CarLog::image(TimeNs at, TimeNs stamp, const std::vector<std::uint8_t>& jpeg) {
  fg::compressed_image(stamp, "camera", jpeg.data(), jpeg.size(), "jpeg", text_);
  write(image_, at, text_);
}

void CarLog::cycle(TimeNs at, const hal::ActuatorCommand& c, const stack::Stack& stack) {
  if (!mounted_) {
    // where the LiDAR sits on the car
    mounted_ = true;
    fg::transform(at, "base", "lidar", layout_.mount_x, layout_.mount_y, layout_.mount_z, 0.0, layout_.mount_pitch,
                  text_);
    write(tf_, at, text_);
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
  write(command_, at, text_);
  const std::optional<hal::StateEstimate>& e = stack.estimate();
  if (e && (!next_pose_ || at >= *next_pose_)) {
    next_pose_ = at + pose_period_;
    fg::pose_in_frame(e->stamp, "map", e->pose.x, e->pose.y, e->pose.yaw, text_);
    write(pose_, at, text_);
    fg::transform(e->stamp, "map", "base", e->pose.x, e->pose.y, 0.0, e->pose.yaw, 0.0, text_);
    write(tf_, at, text_);
  }
  if (!next_map_ || at >= *next_map_) {
    next_map_ = at + kNsPerSecond;
    fg::cones_update(stack.cone_map().cones(), at, "stack_map", text_);
    write(map_, at, text_);
  }
  // the trajectory when it changed, at most twice a second
  const Trajectory& tr = stack.trajectory();
  const bool changed = tr.points.data() != path_of_ || tr.points.size() != path_points_ || tr.length != path_length_;
  if (changed && (!next_path_ || at >= *next_path_) && !tr.empty()) {
    next_path_ = at + kNsPerSecond / 2;
    path_of_ = tr.points.data();
    path_points_ = tr.points.size();
    path_length_ = tr.length;
    std::vector<Vec2> points;
    points.reserve(tr.points.size());
    for (const TrajectoryPoint& p : tr.points) points.push_back(p.position());
    write(path_, at, fg::line_update(points, tr.closed, at, "path").dump());
  }
}

void CarLog::close() { mcap_->close(); }

}  // namespace paddock::car
