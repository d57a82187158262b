#include "autonomy/log/foxglove.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

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

// a cone's r, g, b as drawn
const double* cone_rgb(ConeColor c) {
  static const double blue[3] = {0.1, 0.3, 1.0}, yellow[3] = {1.0, 0.85, 0.0}, small_orange[3] = {1.0, 0.5, 0.0},
                      big_orange[3] = {1.0, 0.35, 0.0}, other[3] = {0.6, 0.6, 0.6};
  switch (c) {
    case ConeColor::Blue: return blue;
    case ConeColor::Yellow: return yellow;
    case ConeColor::SmallOrange: return small_orange;
    case ConeColor::BigOrange: return big_orange;
    default: return other;
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

// ------------------------------------------------------------ JSON text

JsonWriter::JsonWriter(std::string& out) : out_(out) { out_.clear(); }

void JsonWriter::separate() {
  if (comma_) out_ += ',';
  comma_ = false;
}

JsonWriter& JsonWriter::begin_object() {
  separate();
  out_ += '{';
  return *this;
}

JsonWriter& JsonWriter::end_object() {
  out_ += '}';
  comma_ = true;
  return *this;
}

JsonWriter& JsonWriter::begin_array() {
  separate();
  out_ += '[';
  return *this;
}

JsonWriter& JsonWriter::end_array() {
  out_ += ']';
  comma_ = true;
  return *this;
}

JsonWriter& JsonWriter::key(const char* k) {
  string(k);
  out_ += ':';
  comma_ = false;
  return *this;
}

JsonWriter& JsonWriter::number(double v) {
  separate();
  comma_ = true;
  if (!std::isfinite(v)) {
    out_ += "null";
    return *this;
  }
  if (v == 0.0) {
    out_ += std::signbit(v) ? "-0.0" : "0.0";
    return *this;
  }
  // the shortest digits that read back, d.ddde[+-]x, then laid out as
  // nlohmann's format_buffer lays out its digits (k of them, the decimal
  // point n places in): whole numbers to 1e15 with ".0", fractions down to
  // 1e-5 without an exponent, the rest d.ddde+XX
  char sci[32];
  const std::to_chars_result r = std::to_chars(sci, sci + sizeof sci, v, std::chars_format::scientific);
  const char* e = std::find(sci, r.ptr, 'e');
  if (sci[0] == '-') out_ += '-';
  char digits[24];
  int k = 0;
  for (const char* c = sci[0] == '-' ? sci + 1 : sci; c < e; ++c) {
    if (*c != '.') digits[k++] = *c;
  }
  int exponent = 0;
  std::from_chars(e + 1 + (e[1] == '+'), r.ptr, exponent);
  const int n = exponent + 1;
  constexpr int kMinExp = -4, kMaxExp = 15;  // std::numeric_limits<double>::digits10
  if (k <= n && n <= kMaxExp) {
    out_.append(digits, static_cast<std::size_t>(k)).append(static_cast<std::size_t>(n - k), '0') += ".0";
  } else if (0 < n && n <= kMaxExp) {
    out_.append(digits, static_cast<std::size_t>(n)) += '.';
    out_.append(digits + n, static_cast<std::size_t>(k - n));
  } else if (kMinExp < n && n <= 0) {
    out_.append("0.").append(static_cast<std::size_t>(-n), '0').append(digits, static_cast<std::size_t>(k));
  } else {
    out_ += digits[0];
    if (k > 1) (out_ += '.').append(digits + 1, static_cast<std::size_t>(k - 1));
    // at least two digits of exponent, as printf's %g
    char x[16];
    std::snprintf(x, sizeof x, "e%c%02d", n - 1 < 0 ? '-' : '+', std::abs(n - 1));
    out_ += x;
  }
  return *this;
}

JsonWriter& JsonWriter::integer(std::int64_t v) {
  separate();
  comma_ = true;
  char buf[24];
  out_.append(buf, static_cast<std::size_t>(std::to_chars(buf, buf + sizeof buf, v).ptr - buf));
  return *this;
}

JsonWriter& JsonWriter::boolean(bool v) {
  separate();
  comma_ = true;
  out_ += v ? "true" : "false";
  return *this;
}

JsonWriter& JsonWriter::string(const char* s) {
  separate();
  comma_ = true;
  out_ += '"';
  // escaped as dump() escapes: the two-character forms, else \u00XX below a space
  for (; *s; ++s) {
    const auto c = static_cast<unsigned char>(*s);
    switch (c) {
      case '"': out_ += "\\\""; break;
      case '\\': out_ += "\\\\"; break;
      case '\b': out_ += "\\b"; break;
      case '\f': out_ += "\\f"; break;
      case '\n': out_ += "\\n"; break;
      case '\r': out_ += "\\r"; break;
      case '\t': out_ += "\\t"; break;
      default:
        if (c < 0x20) {
          char u[8];
          std::snprintf(u, sizeof u, "\\u%04x", static_cast<unsigned>(c));
          out_ += u;
        } else {
          out_ += static_cast<char>(c);
        }
    }
  }
  out_ += '"';
  return *this;
}

namespace {

// the values above as text (keys in dump()'s order)
void put_stamp(JsonWriter& w, TimeNs t) {
  const TimeNs sec = t >= 0 ? t / 1000000000 : -((-t + 999999999) / 1000000000);
  w.begin_object().key("nsec").integer(t - sec * 1000000000).key("sec").integer(sec).end_object();
}
void put_xyz(JsonWriter& w, double x, double y, double z) {
  w.begin_object().key("x").number(x).key("y").number(y).key("z").number(z).end_object();
}
void put_rotation(JsonWriter& w, double yaw, double pitch) {
  const double cy = std::cos(0.5 * yaw), sy = std::sin(0.5 * yaw), cp = std::cos(0.5 * pitch),
               sp = std::sin(0.5 * pitch);
  w.begin_object().key("w").number(cy * cp).key("x").number(-sy * sp).key("y").number(cy * sp);
  w.key("z").number(sy * cp).end_object();
}
void put_pose(JsonWriter& w, double x, double y, double z, double yaw) {
  w.begin_object().key("orientation");
  put_rotation(w, yaw, 0.0);
  w.key("position");
  put_xyz(w, x, y, z);
  w.end_object();
}
void put_rgba(JsonWriter& w, double r, double g, double b, double a) {
  w.begin_object().key("a").number(a).key("b").number(b).key("g").number(g).key("r").number(r).end_object();
}

}  // namespace

void transform(TimeNs at, const char* parent, const char* child, double x, double y, double z, double yaw,
               double pitch, std::string& out) {
  JsonWriter w(out);
  w.begin_object().key("child_frame_id").string(child).key("parent_frame_id").string(parent).key("rotation");
  put_rotation(w, yaw, pitch);
  w.key("timestamp");
  put_stamp(w, at);
  w.key("translation");
  put_xyz(w, x, y, z);
  w.end_object();
}

void pose_in_frame(TimeNs at, const char* frame, double x, double y, double yaw, std::string& out) {
  JsonWriter w(out);
  w.begin_object().key("frame_id").string(frame).key("pose");
  put_pose(w, x, y, 0.0, yaw);
  w.key("timestamp");
  put_stamp(w, at);
  w.end_object();
}

void cones_update(const std::vector<Cone>& cones, TimeNs at, const char* id, std::string& out) {
  JsonWriter w(out);
  w.begin_object().key("deletions").begin_array().end_array().key("entities").begin_array();
  // the entity (as entity() has it): its cylinders, one a cone
  w.begin_object().key("cylinders").begin_array();
  for (const Cone& c : cones) {
    const bool big = c.color == ConeColor::BigOrange;
    const double h = big ? 0.505 : 0.325, wd = big ? 0.285 : 0.228;
    w.begin_object().key("bottom_scale").number(1.0).key("color");
    const double* rgb = cone_rgb(c.color);
    put_rgba(w, rgb[0], rgb[1], rgb[2], 1.0);
    w.key("pose");
    put_pose(w, c.position.x, c.position.y, 0.5 * h, 0.0);
    w.key("size");
    put_xyz(w, wd, wd, h);
    w.key("top_scale").number(0.2).end_object();
  }
  w.end_array().key("frame_id").string("map").key("frame_locked").boolean(false).key("id").string(id);
  w.key("lifetime");
  put_stamp(w, 0);
  w.key("lines").begin_array().end_array().key("timestamp");
  put_stamp(w, at);
  w.end_object().end_array().end_object();
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
