#pragma once
// Foxglove's well-known JSON schemas (https://docs.foxglove.dev/docs/
// visualization/message-schemas) as JSON Schema, and their values: what a
// run's log (and the car's) writes so Foxglove draws the car, the scan, the
// cones and the path in 3D.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "autonomy/common/cone.h"
#include "autonomy/common/time.h"

namespace paddock::log::foxglove {

using nlohmann::json;

// the schemas, each with its "title" (the schema's name in the MCAP file)
std::string frame_transform_schema();
std::string pose_in_frame_schema();
std::string scene_update_schema();
std::string point_cloud_schema();
std::string compressed_image_schema();
// paddock's own JSON messages: an object of these properties named `title`
std::string object_schema(const char* title, json properties);
json number_schema();
json integer_schema();
json string_schema();
json boolean_schema();
json array_schema(json items);
json object_of(json properties);

// the values
json stamp(TimeNs t);  // {sec, nsec}, nsec in [0, 1e9)
json position(double x, double y, double z);
// yaw about z, then pitch about the new y: q = q_z(yaw) q_y(pitch)
json rotation(double yaw, double pitch = 0.0);
json pose(double x, double y, double z, double yaw);
json rgba(double r, double g, double b, double a = 1.0);

// JSON text written straight into a string (replaced; its storage kept),
// the text json::dump() gives for the same value: numbers in its form (the
// shortest that reads back, "1.0" for a whole one, an exponent outside
// 1e-5 .. 1e15), strings escaped as it does. The caller writes each
// object's keys in dump()'s order (sorted: nlohmann's objects are
// std::maps). For the messages logged every cycle: no tree of maps to
// build, walk and free.
class JsonWriter {
 public:
  explicit JsonWriter(std::string& out);
  JsonWriter& begin_object();
  JsonWriter& end_object();
  JsonWriter& begin_array();
  JsonWriter& end_array();
  JsonWriter& key(const char* k);
  JsonWriter& number(double v);  // NaN and infinities as null, as dump()
  JsonWriter& integer(std::int64_t v);
  JsonWriter& boolean(bool v);
  JsonWriter& string(const char* s);

 private:
  void separate();  // the comma before a value or key that follows another
  std::string& out_;
  bool comma_ = false;
};

// the messages logged every cycle, as their JSON text into `out` (replaced):
// foxglove.FrameTransform
void transform(TimeNs at, const char* parent, const char* child, double x, double y, double z, double yaw,
               double pitch, std::string& out);
// foxglove.PoseInFrame
void pose_in_frame(TimeNs at, const char* frame, double x, double y, double yaw, std::string& out);
// foxglove.SceneUpdate: the cones as one entity `id` of cylinders (tapered:
// a cone) in the map frame, coloured as they are
void cones_update(const std::vector<Cone>& cones, TimeNs at, const char* id, std::string& out);
// foxglove.SceneUpdate: a line strip `id` through the points (z = 2 cm), closed if asked
json line_update(const std::vector<Vec2>& points, bool closed, TimeNs at, const char* id);
// the two messages with a `bytes` field, as their JSON text into `out`
// (replaced; its storage kept for the next): the text json::dump() gives,
// the field's base64 spliced in rather than escaped character by character
// foxglove.PointCloud of `points` float32 x, y, z, intensity (xyzi: 4 a point), in `frame`
void point_cloud(TimeNs at, const char* frame, const float* xyzi, std::size_t points, std::string& out);
// foxglove.CompressedImage: an image's n bytes in `format` ("jpeg") in `frame`
void compressed_image(TimeNs at, const char* frame, const std::uint8_t* data, std::size_t n, const char* format,
                      std::string& out);
// RFC 4648 base64 (a JSON `bytes` field); appended to `out`
std::string base64(const std::uint8_t* p, std::size_t n);
void append_base64(std::string& out, const std::uint8_t* p, std::size_t n);

}  // namespace paddock::log::foxglove
