#include "sim/runner/run_log.h"

#include <cmath>
#include <cstring>
#include <variant>

#include <nlohmann/json.hpp>

#include "autonomy/hal/json.h"
#include "sim/runner/files.h"
#include "sim/runner/scenario.h"
#include "sim/runner/simulation.h"
#include "sim/vehicle/vehicle.h"

namespace paddock::runner {
namespace {

using nlohmann::json;

// ------------------------------------------------- Foxglove's JSON schemas
//
// the well-known schemas' fields (https://docs.foxglove.dev/docs/
// visualization/message-schemas), as JSON Schema: what Foxglove reads a
// JSON channel of that schema name with

json number() { return {{"type", "number"}}; }
json object(json properties) { return {{"type", "object"}, {"properties", std::move(properties)}}; }
json time_schema() { return object({{"sec", {{"type", "integer"}}}, {"nsec", {{"type", "integer"}}}}); }
json vector3() { return object({{"x", number()}, {"y", number()}, {"z", number()}}); }
json quaternion() { return object({{"x", number()}, {"y", number()}, {"z", number()}, {"w", number()}}); }
json pose_schema() { return object({{"position", vector3()}, {"orientation", quaternion()}}); }
json color() { return object({{"r", number()}, {"g", number()}, {"b", number()}, {"a", number()}}); }
json array_of(json items) { return {{"type", "array"}, {"items", std::move(items)}}; }
json string_schema() { return {{"type", "string"}}; }

std::string frame_transform_schema() {
  json s = object({{"timestamp", time_schema()},
                   {"parent_frame_id", string_schema()},
                   {"child_frame_id", string_schema()},
                   {"translation", vector3()},
                   {"rotation", quaternion()}});
  s["title"] = "foxglove.FrameTransform";
  return s.dump();
}

std::string pose_in_frame_schema() {
  json s = object({{"timestamp", time_schema()}, {"frame_id", string_schema()}, {"pose", pose_schema()}});
  s["title"] = "foxglove.PoseInFrame";
  return s.dump();
}

std::string scene_update_schema() {
  const json cylinder = object({{"pose", pose_schema()},
                                {"size", vector3()},
                                {"bottom_scale", number()},
                                {"top_scale", number()},
                                {"color", color()}});
  const json line = object({{"type", {{"type", "integer"}}},
                            {"pose", pose_schema()},
                            {"thickness", number()},
                            {"scale_invariant", {{"type", "boolean"}}},
                            {"points", array_of(vector3())},
                            {"color", color()},
                            {"colors", array_of(color())},
                            {"indices", array_of({{"type", "integer"}})}});
  const json entity = object({{"timestamp", time_schema()},
                              {"frame_id", string_schema()},
                              {"id", string_schema()},
                              {"lifetime", time_schema()},
                              {"frame_locked", {{"type", "boolean"}}},
                              {"cylinders", array_of(cylinder)},
                              {"lines", array_of(line)}});
  json s = object({{"deletions", array_of(object({{"timestamp", time_schema()},
                                                  {"type", {{"type", "integer"}}},
                                                  {"id", string_schema()}}))},
                   {"entities", array_of(entity)}});
  s["title"] = "foxglove.SceneUpdate";
  return s.dump();
}

std::string point_cloud_schema() {
  const json field = object({{"name", string_schema()}, {"offset", {{"type", "integer"}}}, {"type", {{"type", "integer"}}}});
  json s = object({{"timestamp", time_schema()},
                   {"frame_id", string_schema()},
                   {"pose", pose_schema()},
                   {"point_stride", {{"type", "integer"}}},
                   {"fields", array_of(field)},
                   {"data", {{"type", "string"}, {"contentEncoding", "base64"}}}});
  s["title"] = "foxglove.PointCloud";
  return s.dump();
}

// paddock's own JSON messages: their fields as the HAL's structs have them
std::string paddock_schema(const char* title, json properties) {
  json s = object(std::move(properties));
  s["title"] = title;
  return s.dump();
}

// ------------------------------------------------------------- the values

json stamp_of(TimeNs t) {
  const TimeNs sec = t >= 0 ? t / 1000000000 : -((-t + 999999999) / 1000000000);
  return {{"sec", sec}, {"nsec", t - sec * 1000000000}};
}

json position(double x, double y, double z) { return {{"x", x}, {"y", y}, {"z", z}}; }
// yaw about z, then pitch about the new y: q = q_z(yaw) q_y(pitch)
json rotation(double yaw, double pitch = 0.0) {
  const double cy = std::cos(0.5 * yaw), sy = std::sin(0.5 * yaw), cp = std::cos(0.5 * pitch),
               sp = std::sin(0.5 * pitch);
  return {{"x", -sy * sp}, {"y", cy * sp}, {"z", sy * cp}, {"w", cy * cp}};
}
json pose_json(double x, double y, double z, double yaw) {
  return {{"position", position(x, y, z)}, {"orientation", rotation(yaw)}};
}
json rgba(double r, double g, double b, double a = 1.0) { return {{"r", r}, {"g", g}, {"b", b}, {"a", a}}; }

json cone_color(ConeColor c) {
  switch (c) {
    case ConeColor::Blue: return rgba(0.1, 0.3, 1.0);
    case ConeColor::Yellow: return rgba(1.0, 0.85, 0.0);
    case ConeColor::SmallOrange: return rgba(1.0, 0.5, 0.0);
    case ConeColor::BigOrange: return rgba(1.0, 0.35, 0.0);
    default: return rgba(0.6, 0.6, 0.6);
  }
}

// the cones as one entity of cylinders (a cone: a cylinder whose top is
// scaled down), in the map frame
json cones_update(const std::vector<Cone>& cones, TimeNs at, const char* id) {
  json cylinders = json::array();
  for (const Cone& c : cones) {
    const bool big = c.color == ConeColor::BigOrange;
    const double h = big ? 0.505 : 0.325, w = big ? 0.285 : 0.228;
    cylinders.push_back({{"pose", pose_json(c.position.x, c.position.y, 0.5 * h, 0.0)},
                         {"size", position(w, w, h)},
                         {"bottom_scale", 1.0},
                         {"top_scale", 0.2},
                         {"color", cone_color(c.color)}});
  }
  json entity = {{"timestamp", stamp_of(at)}, {"frame_id", "map"}, {"id", id},
                 {"lifetime", stamp_of(0)},   {"frame_locked", false}, {"cylinders", cylinders},
                 {"lines", json::array()}};
  return {{"deletions", json::array()}, {"entities", json::array({entity})}};
}

json transform(TimeNs at, const char* parent, const char* child, double x, double y, double z, double yaw,
               double pitch = 0.0) {
  return {{"timestamp", stamp_of(at)},
          {"parent_frame_id", parent},
          {"child_frame_id", child},
          {"translation", position(x, y, z)},
          {"rotation", rotation(yaw, pitch)}};
}

// RFC 4648 base64 (what a JSON `bytes` field holds)
std::string base64(const std::uint8_t* p, std::size_t n) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((n + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < n; i += 3) {
    const std::uint32_t v = (std::uint32_t{p[i]} << 16) | (std::uint32_t{p[i + 1]} << 8) | p[i + 2];
    out += k[(v >> 18) & 63];
    out += k[(v >> 12) & 63];
    out += k[(v >> 6) & 63];
    out += k[v & 63];
  }
  if (i < n) {
    const std::uint32_t v = (std::uint32_t{p[i]} << 16) | (i + 1 < n ? std::uint32_t{p[i + 1]} << 8 : 0u);
    out += k[(v >> 18) & 63];
    out += k[(v >> 12) & 63];
    out += i + 1 < n ? k[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

}  // namespace

RunLog::RunLog(const std::string& path, const Scenario& sc) {
  if (sc.hal.transport == Transport::Memory)
    throw UserError(sc.source + ": --log records the car's wires: it needs [hal] transport = wire (or udp) (include = sensors/ouster.ini names the sensors' files; scenarios/fsg_2023_autocross_wire.ini is an example)");
  log::McapWriterOptions o;
  o.profile = "";
  o.library = "paddock";
  try {
    mcap_ = std::make_unique<log::McapWriter>(std::make_unique<log::FileSink>(path), o);
  } catch (const std::exception& e) {
    throw UserError(path + ": cannot write the log: " + e.what());
  }
  // what a reader needs to decode the wires and rerun the stack
  if (sc.lidar_info) {
    const std::string meta = hal::ouster::to_json(*sc.lidar_info);
    mcap_->write_attachment({0, 0, "lidar_metadata.json", "application/json",
                             std::vector<std::uint8_t>(meta.begin(), meta.end())});
    info_ = sc.lidar_info;
    decoder_ = std::make_unique<hal::ouster::Decoder>(*info_, sc.lidar);
  }
  mcap_->write_attachment({0, 0, "car.dbc", "text/plain", std::vector<std::uint8_t>(sc.dbc_text.begin(), sc.dbc_text.end())});
  const std::string track = read_file(sc.track_path);
  mcap_->write_attachment({0, 0, "track.csv", "text/csv", std::vector<std::uint8_t>(track.begin(), track.end())});
  const std::string resolved = resolved_ini(sc);
  mcap_->write_attachment({0, 0, "scenario.ini", "text/plain", std::vector<std::uint8_t>(resolved.begin(), resolved.end())});
  mcap_->write_metadata("paddock", {{"scenario", sc.source}, {"seed", std::to_string(sc.scenario.seed)},
                                    {"transport", sc.hal.transport == Transport::Udp ? "udp" : "wire"}});

  packets_ = channel("/lidar/packets", "", "ouster.lidar_packet.legacy");
  can_rx_ = channel("/can/rx", "", "socketcan.can_frame");
  can_tx_ = channel("/can/tx", "", "socketcan.can_frame");
  const json box = object({{"x_min", number()}, {"y_min", number()}, {"x_max", number()}, {"y_max", number()},
                           {"color", {{"type", "integer"}}}, {"confidence", number()}});
  detections_ = channel("/hal/detections",
                        paddock_schema("paddock.CameraDetections", {{"stamp", {{"type", "integer"}}},
                                                                    {"width", {{"type", "integer"}}},
                                                                    {"height", {{"type", "integer"}}},
                                                                    {"boxes", array_of(box)}}),
                        "json");
  const json cone = object({{"x", number()}, {"y", number()}, {"color", {{"type", "integer"}}},
                            {"colour_from_camera", {{"type", "boolean"}}}});
  cones_ = channel("/hal/cones",
                   paddock_schema("paddock.ConeDetections", {{"stamp", {{"type", "integer"}}},
                                                             {"cones", array_of(cone)},
                                                             {"free_range", array_of(number())}}),
                   "json");
  state_ = channel("/hal/state",
                   paddock_schema("paddock.StateEstimate", {{"stamp", {{"type", "integer"}}}, {"x", number()},
                                                            {"y", number()}, {"yaw", number()}, {"vx", number()},
                                                            {"vy", number()}, {"yaw_rate", number()}}),
                   "json");
  tf_ = channel("/tf", frame_transform_schema(), "json");
  pose_ = channel("/stack/pose", pose_in_frame_schema(), "json");
  truth_pose_ = channel("/truth/pose", pose_in_frame_schema(), "json");
  command_ = channel("/stack/command",
                     paddock_schema("paddock.ActuatorCommand", {{"stamp", {{"type", "integer"}}},
                                                                {"steering_angle", number()},
                                                                {"throttle", number()},
                                                                {"brake", number()},
                                                                {"yaw_moment", number()},
                                                                {"as_state", string_schema()}}),
                     "json");
  map_ = channel("/stack/map", scene_update_schema(), "json");
  path_ = channel("/stack/path", scene_update_schema(), "json");
  truth_cones_ = channel("/truth/cones", scene_update_schema(), "json");
  points_ = channel("/lidar/points", point_cloud_schema(), "json");
  log_every_ = std::max(1, sc.sim.physics_rate / sc.sim.log_rate);
}

RunLog::~RunLog() = default;

std::uint16_t RunLog::channel(const std::string& topic, const std::string& schema, const std::string& encoding) {
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

void RunLog::write(std::uint16_t ch, TimeNs at, const std::uint8_t* data, std::size_t size) {
  const auto t = static_cast<std::uint64_t>(std::max<TimeNs>(at, 0));
  mcap_->write(ch, sequence_[ch]++, t, t, data, size);
}

void RunLog::write(std::uint16_t ch, TimeNs at, const std::string& data) {
  write(ch, at, reinterpret_cast<const std::uint8_t*>(data.data()), data.size());
}

void RunLog::lidar_packet(TimeNs at, const std::uint8_t* data, std::size_t size) {
  write(packets_, at, data, size);
  if (!decoder_) return;
  decoder_->push(data, size);
  while (std::optional<hal::LidarScan> scan = decoder_->pop()) {
    if (rotations_++ % kPointCloudEvery != 0) continue;
    // x, y, z, intensity as float32, in the sensor frame as it stood (raw:
    // not deskewed)
    std::vector<std::uint8_t> bytes(scan->points.size() * 16);
    for (std::size_t i = 0; i < scan->points.size(); ++i) {
      const hal::LidarPoint& p = scan->points[i];
      const float v[4] = {p.x, p.y, p.z, p.intensity};
      std::memcpy(&bytes[i * 16], v, sizeof v);
    }
    json fields = json::array();
    const char* names[4] = {"x", "y", "z", "intensity"};
    for (int k = 0; k < 4; ++k) fields.push_back({{"name", names[k]}, {"offset", 4 * k}, {"type", 7}});
    const json cloud = {{"timestamp", stamp_of(scan->end)},
                        {"frame_id", "lidar"},
                        {"pose", pose_json(0.0, 0.0, 0.0, 0.0)},
                        {"point_stride", 16},
                        {"fields", fields},
                        {"data", base64(bytes.data(), bytes.size())}};
    write(points_, at, cloud.dump());
  }
}

void RunLog::can_frame(TimeNs at, bool to_stack, const std::uint8_t* frame) {
  write(to_stack ? can_rx_ : can_tx_, at, frame, hal::kSocketCanFrameSize);
}

void RunLog::message(TimeNs at, const hal::SensorMessage& m) {
  // what travels on a wire is logged as its bytes (lidar_packet, can_frame)
  const std::optional<std::string> j = hal::to_json(m);
  if (!j) return;
  const std::uint16_t ch = std::holds_alternative<hal::CameraDetections>(m) ? detections_
                           : std::holds_alternative<hal::ConeDetections>(m) ? cones_
                                                                            : state_;
  write(ch, at, *j);
}

void RunLog::observe(const SimModel& model, SimState& s) {
  if (!started_) {
    // (the run taps the HAL from its first instant: run(..., tap))
    started_ = true;
    // where the LiDAR sits on the car
    const sensors::LidarParams& l = model.scenario.lidar;
    write(tf_, s.now, transform(s.now, "base", "lidar", l.mount_x, l.mount_y, l.mount_z, 0.0, l.mount_pitch).dump());
  }
  const TimeNs at = s.now;
  // the stack's command as it sent it, each control cycle (/can/tx has it
  // as the wire carried it)
  if (s.controlled && s.hal.sent()) {
    const hal::ActuatorCommand& c = *s.hal.sent();
    write(command_, at,
          json{{"stamp", c.stamp}, {"steering_angle", c.steering_angle}, {"throttle", c.throttle},
               {"brake", c.brake}, {"yaw_moment", c.yaw_moment}, {"as_state", hal::to_string(c.as_state)}}
              .dump());
  }
  // the poses at the log rate: estimated (and as /tf for the 3D view), true
  if (s.k % log_every_ == 0) {
    const Pose2 truth = vehicle::base_pose(model.scenario.vehicle, s.car);
    write(truth_pose_, at,
          json{{"timestamp", stamp_of(at)}, {"frame_id", "map"}, {"pose", pose_json(truth.x, truth.y, 0.0, truth.yaw)}}
              .dump());
    if (const std::optional<hal::StateEstimate>& e = s.stack.estimate()) {
      write(pose_, at,
            json{{"timestamp", stamp_of(e->stamp)}, {"frame_id", "map"},
                 {"pose", pose_json(e->pose.x, e->pose.y, 0.0, e->pose.yaw)}}
                .dump());
      write(tf_, at, transform(e->stamp, "map", "base", e->pose.x, e->pose.y, 0.0, e->pose.yaw).dump());
    }
  }
  // the maps once a second
  if (at >= next_map_) {
    next_map_ = at + 1000000000;
    write(map_, at, cones_update(s.stack.cone_map().cones(), at, "stack_map").dump());
    std::vector<Cone> truth(static_cast<std::size_t>(s.cones.cone_count()));
    for (int i = 0; i < s.cones.cone_count(); ++i)
      truth[static_cast<std::size_t>(i)] = {s.cones.cone_position(i), s.cones.cone(i).color};
    write(truth_cones_, at, cones_update(truth, at, "truth_cones").dump());
  }
  // the trajectory when it changed, at most twice a second
  const Trajectory& tr = s.stack.trajectory();
  const bool changed = tr.points.data() != path_of_ || tr.points.size() != path_points_ || tr.length != path_length_;
  if (changed && at >= next_path_ && !tr.empty()) {
    next_path_ = at + 500000000;
    path_of_ = tr.points.data();
    path_points_ = tr.points.size();
    path_length_ = tr.length;
    json points = json::array();
    for (const TrajectoryPoint& p : tr.points) points.push_back(position(p.x, p.y, 0.02));
    if (tr.closed) points.push_back(position(tr.points.front().x, tr.points.front().y, 0.02));
    const json line = {{"type", 0},
                       {"pose", pose_json(0.0, 0.0, 0.0, 0.0)},
                       {"thickness", 0.08},
                       {"scale_invariant", false},
                       {"points", points},
                       {"color", rgba(0.1, 0.9, 0.3)},
                       {"colors", json::array()},
                       {"indices", json::array()}};
    const json entity = {{"timestamp", stamp_of(at)}, {"frame_id", "map"},    {"id", "path"},
                         {"lifetime", stamp_of(0)},   {"frame_locked", false}, {"cylinders", json::array()},
                         {"lines", json::array({line})}};
    write(path_, at, json{{"deletions", json::array()}, {"entities", json::array({entity})}}.dump());
  }
}

void RunLog::close() { mcap_->close(); }


}  // namespace paddock::runner
