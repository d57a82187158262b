#include "autonomy/log/foxglove.h"

#include <cmath>

namespace paddock::log::foxglove {

json number_schema() { return {{"type", "number"}}; }
json integer_schema() { return {{"type", "integer"}}; }
json string_schema() { return {{"type", "string"}}; }
json boolean_schema() { return {{"type", "boolean"}}; }
json array_schema(json items) { return {{"type", "array"}, {"items", std::move(items)}}; }
json object_of(json properties) { return {{"type", "object"}, {"properties", std::move(properties)}}; }

namespace {

json time_schema() { return object_of({{"sec", integer_schema()}, {"nsec", integer_schema()}}); }
json vector3() { return object_of({{"x", number_schema()}, {"y", number_schema()}, {"z", number_schema()}}); }
json quaternion() {
  return object_of({{"x", number_schema()}, {"y", number_schema()}, {"z", number_schema()}, {"w", number_schema()}});
}
json pose_schema() { return object_of({{"position", vector3()}, {"orientation", quaternion()}}); }
json color() {
  return object_of({{"r", number_schema()}, {"g", number_schema()}, {"b", number_schema()}, {"a", number_schema()}});
}
std::string titled(json s, const char* title) {
  s["title"] = title;
  return s.dump();
}

json cone_color(ConeColor c) {
  switch (c) {
    case ConeColor::Blue: return rgba(0.1, 0.3, 1.0);
    case ConeColor::Yellow: return rgba(1.0, 0.85, 0.0);
    case ConeColor::SmallOrange: return rgba(1.0, 0.5, 0.0);
    case ConeColor::BigOrange: return rgba(1.0, 0.35, 0.0);
    default: return rgba(0.6, 0.6, 0.6);
  }
}

json entity(TimeNs at, const char* id, json cylinders, json lines) {
  const json e = {{"timestamp", stamp(at)},    {"frame_id", "map"},     {"id", id},
                  {"lifetime", stamp(0)},      {"frame_locked", false}, {"cylinders", std::move(cylinders)},
                  {"lines", std::move(lines)}};
  return {{"deletions", json::array()}, {"entities", json::array({e})}};
}

// `fields` (an object) with "data": the n bytes in base64, as the JSON text
// dump() gives: nlohmann's objects keep their keys sorted (std::map), and
// "data" sorts before the fields' names, so it opens the object
void with_data(const json& fields, const std::uint8_t* data, std::size_t n, std::string& out) {
  const std::string rest = fields.dump();  // {"...": ...}: small
  out.assign("{\"data\":\"");
  out.reserve(out.size() + (n + 2) / 3 * 4 + rest.size() + 1);
  append_base64(out, data, n);
  out += "\",";
  out.append(rest, 1, std::string::npos);
}

}  // namespace

std::string frame_transform_schema() {
  return titled(object_of({{"timestamp", time_schema()},
                           {"parent_frame_id", string_schema()},
                           {"child_frame_id", string_schema()},
                           {"translation", vector3()},
                           {"rotation", quaternion()}}),
                "foxglove.FrameTransform");
}

std::string pose_in_frame_schema() {
  return titled(object_of({{"timestamp", time_schema()}, {"frame_id", string_schema()}, {"pose", pose_schema()}}),
                "foxglove.PoseInFrame");
}

std::string scene_update_schema() {
  const json cylinder = object_of({{"pose", pose_schema()},
                                   {"size", vector3()},
                                   {"bottom_scale", number_schema()},
                                   {"top_scale", number_schema()},
                                   {"color", color()}});
  const json line = object_of({{"type", integer_schema()},
                               {"pose", pose_schema()},
                               {"thickness", number_schema()},
                               {"scale_invariant", boolean_schema()},
                               {"points", array_schema(vector3())},
                               {"color", color()},
                               {"colors", array_schema(color())},
                               {"indices", array_schema(integer_schema())}});
  const json e = object_of({{"timestamp", time_schema()},
                            {"frame_id", string_schema()},
                            {"id", string_schema()},
                            {"lifetime", time_schema()},
                            {"frame_locked", boolean_schema()},
                            {"cylinders", array_schema(cylinder)},
                            {"lines", array_schema(line)}});
  return titled(object_of({{"deletions", array_schema(object_of({{"timestamp", time_schema()},
                                                                  {"type", integer_schema()},
                                                                  {"id", string_schema()}}))},
                           {"entities", array_schema(e)}}),
                "foxglove.SceneUpdate");
}

std::string point_cloud_schema() {
  const json field = object_of({{"name", string_schema()}, {"offset", integer_schema()}, {"type", integer_schema()}});
  return titled(object_of({{"timestamp", time_schema()},
                           {"frame_id", string_schema()},
                           {"pose", pose_schema()},
                           {"point_stride", integer_schema()},
                           {"fields", array_schema(field)},
                           {"data", {{"type", "string"}, {"contentEncoding", "base64"}}}}),
                "foxglove.PointCloud");
}

std::string compressed_image_schema() {
  return titled(object_of({{"timestamp", time_schema()},
                           {"frame_id", string_schema()},
                           {"data", {{"type", "string"}, {"contentEncoding", "base64"}}},
                           {"format", string_schema()}}),
                "foxglove.CompressedImage");
}

void compressed_image(TimeNs at, const char* frame, const std::uint8_t* data, std::size_t n, const char* format,
                      std::string& out) {
  with_data({{"timestamp", stamp(at)}, {"frame_id", frame}, {"format", format}}, data, n, out);
}

std::string object_schema(const char* title, json properties) { return titled(object_of(std::move(properties)), title); }

json stamp(TimeNs t) {
  const TimeNs sec = t >= 0 ? t / 1000000000 : -((-t + 999999999) / 1000000000);
  return {{"sec", sec}, {"nsec", t - sec * 1000000000}};
}

json position(double x, double y, double z) { return {{"x", x}, {"y", y}, {"z", z}}; }

json rotation(double yaw, double pitch) {
  const double cy = std::cos(0.5 * yaw), sy = std::sin(0.5 * yaw), cp = std::cos(0.5 * pitch),
               sp = std::sin(0.5 * pitch);
  return {{"x", -sy * sp}, {"y", cy * sp}, {"z", sy * cp}, {"w", cy * cp}};
}

json pose(double x, double y, double z, double yaw) { return {{"position", position(x, y, z)}, {"orientation", rotation(yaw)}}; }

json rgba(double r, double g, double b, double a) { return {{"r", r}, {"g", g}, {"b", b}, {"a", a}}; }

json transform(TimeNs at, const char* parent, const char* child, double x, double y, double z, double yaw,
               double pitch) {
  return {{"timestamp", stamp(at)},
          {"parent_frame_id", parent},
          {"child_frame_id", child},
          {"translation", position(x, y, z)},
          {"rotation", rotation(yaw, pitch)}};
}

json pose_in_frame(TimeNs at, const char* frame, double x, double y, double yaw) {
  return {{"timestamp", stamp(at)}, {"frame_id", frame}, {"pose", pose(x, y, 0.0, yaw)}};
}

json cones_update(const std::vector<Cone>& cones, TimeNs at, const char* id) {
  json cylinders = json::array();
  for (const Cone& c : cones) {
    const bool big = c.color == ConeColor::BigOrange;
    const double h = big ? 0.505 : 0.325, w = big ? 0.285 : 0.228;
    cylinders.push_back({{"pose", pose(c.position.x, c.position.y, 0.5 * h, 0.0)},
                         {"size", position(w, w, h)},
                         {"bottom_scale", 1.0},
                         {"top_scale", 0.2},
                         {"color", cone_color(c.color)}});
  }
  return entity(at, id, cylinders, json::array());
}

json line_update(const std::vector<Vec2>& points, bool closed, TimeNs at, const char* id) {
  json pts = json::array();
  for (const Vec2& p : points) pts.push_back(position(p.x, p.y, 0.02));
  if (closed && !points.empty()) pts.push_back(position(points.front().x, points.front().y, 0.02));
  const json line = {{"type", 0},
                     {"pose", pose(0.0, 0.0, 0.0, 0.0)},
                     {"thickness", 0.08},
                     {"scale_invariant", false},
                     {"points", pts},
                     {"color", rgba(0.1, 0.9, 0.3)},
                     {"colors", json::array()},
                     {"indices", json::array()}};
  return entity(at, id, json::array(), json::array({line}));
}

void point_cloud(TimeNs at, const char* frame, const float* xyzi, std::size_t points, std::string& out) {
  json fields = json::array();
  const char* names[4] = {"x", "y", "z", "intensity"};
  for (int k = 0; k < 4; ++k) fields.push_back({{"name", names[k]}, {"offset", 4 * k}, {"type", 7}});  // 7: float32
  // the floats' bytes as they lie in memory (little-endian, as the schema's float32)
  with_data({{"timestamp", stamp(at)},
             {"frame_id", frame},
             {"pose", pose(0.0, 0.0, 0.0, 0.0)},
             {"point_stride", 16},
             {"fields", fields}},
            reinterpret_cast<const std::uint8_t*>(xyzi), 4 * sizeof(float) * points, out);
}

std::string base64(const std::uint8_t* p, std::size_t n) {
  std::string out;
  append_base64(out, p, n);
  return out;
}

void append_base64(std::string& out, const std::uint8_t* p, std::size_t n) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  // the text's room made at once, then written through a pointer
  const std::size_t start = out.size();
  out.resize(start + (n + 2) / 3 * 4);
  char* o = &out[start];
  std::size_t i = 0;
  for (; i + 2 < n; i += 3) {
    const std::uint32_t v = (std::uint32_t{p[i]} << 16) | (std::uint32_t{p[i + 1]} << 8) | p[i + 2];
    *o++ = k[(v >> 18) & 63];
    *o++ = k[(v >> 12) & 63];
    *o++ = k[(v >> 6) & 63];
    *o++ = k[v & 63];
  }
  if (i < n) {
    const std::uint32_t v = (std::uint32_t{p[i]} << 16) | (i + 1 < n ? std::uint32_t{p[i + 1]} << 8 : 0u);
    *o++ = k[(v >> 18) & 63];
    *o++ = k[(v >> 12) & 63];
    *o++ = i + 1 < n ? k[(v >> 6) & 63] : '=';
    *o++ = '=';
  }
}

}  // namespace paddock::log::foxglove
