#include "autonomy/hal/json.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <type_traits>
#include <variant>

#include <nlohmann/json.hpp>

namespace paddock::hal {
namespace {

using nlohmann::json;

ConeColor color_of(const json& j) {
  const int c = j.get<int>();
  if (c < 0 || c > static_cast<int>(ConeColor::Unknown))
    throw std::invalid_argument("color " + std::to_string(c) + " is no cone colour (0..4)");
  return static_cast<ConeColor>(c);
}

TimeNs stamp_of(const json& j) {
  const TimeNs t = j.at("stamp").get<TimeNs>();
  if (t < 0) throw std::invalid_argument("stamp " + std::to_string(t) + " is before 0");
  return t;
}

}  // namespace

std::optional<std::string> to_json(const SensorMessage& m) {
  return std::visit(
      [](const auto& msg) -> std::optional<std::string> {
        using T = std::decay_t<decltype(msg)>;
        if constexpr (std::is_same_v<T, CameraDetections>) {
          json boxes = json::array();
          for (const CameraBox& b : msg.boxes)
            boxes.push_back({{"x_min", b.x_min}, {"y_min", b.y_min}, {"x_max", b.x_max}, {"y_max", b.y_max},
                             {"color", static_cast<int>(b.color)}, {"confidence", b.confidence}});
          return json{{"type", "camera_detections"}, {"stamp", msg.stamp}, {"width", msg.width},
                      {"height", msg.height}, {"boxes", boxes}}
              .dump();
        } else if constexpr (std::is_same_v<T, ConeDetections>) {
          json cones = json::array();
          for (const DetectedCone& c : msg.cones)
            cones.push_back({{"x", c.position.x}, {"y", c.position.y}, {"color", static_cast<int>(c.color)},
                             {"colour_from_camera", c.colour_from_camera}});
          json free = json::array();
          for (const float f : msg.free_range) free.push_back(std::isfinite(f) ? json(f) : json(nullptr));
          return json{{"type", "cone_detections"}, {"stamp", msg.stamp}, {"cones", cones}, {"free_range", free}}.dump();
        } else if constexpr (std::is_same_v<T, StateEstimate>) {
          return json{{"type", "state_estimate"}, {"stamp", msg.stamp}, {"x", msg.pose.x}, {"y", msg.pose.y},
                      {"yaw", msg.pose.yaw}, {"vx", msg.vx}, {"vy", msg.vy}, {"yaw_rate", msg.yaw_rate}}
              .dump();
        } else {
          return std::nullopt;  // a wire carries it
        }
      },
      m);
}

SensorMessage message_from_json(const char* data, std::size_t size) {
  json j;
  try {
    j = json::parse(data, data + size);
  } catch (const json::exception& e) {
    throw std::invalid_argument(std::string("no JSON: ") + e.what());
  }
  try {
    if (!j.is_object()) throw std::invalid_argument("expected a JSON object");
    const std::string type = j.at("type").get<std::string>();
    if (type == "camera_detections") {
      CameraDetections d;
      d.stamp = stamp_of(j);
      d.width = j.at("width").get<int>();
      d.height = j.at("height").get<int>();
      for (const json& b : j.at("boxes"))
        d.boxes.push_back({b.at("x_min").get<double>(), b.at("y_min").get<double>(), b.at("x_max").get<double>(),
                           b.at("y_max").get<double>(), color_of(b.at("color")), b.at("confidence").get<double>()});
      return d;
    }
    if (type == "cone_detections") {
      ConeDetections d;
      d.stamp = stamp_of(j);
      for (const json& c : j.at("cones"))
        d.cones.push_back({{c.at("x").get<double>(), c.at("y").get<double>()}, color_of(c.at("color")),
                           c.at("colour_from_camera").get<bool>()});
      for (const json& f : j.at("free_range"))
        d.free_range.push_back(f.is_null() ? std::numeric_limits<float>::infinity() : f.get<float>());
      return d;
    }
    if (type == "state_estimate") {
      StateEstimate s;
      s.stamp = stamp_of(j);
      s.pose = {j.at("x").get<double>(), j.at("y").get<double>(), j.at("yaw").get<double>()};
      s.vx = j.at("vx").get<double>();
      s.vy = j.at("vy").get<double>();
      s.yaw_rate = j.at("yaw_rate").get<double>();
      return s;
    }
    throw std::invalid_argument("type \"" + type +
                                "\" is none of camera_detections, cone_detections, state_estimate");
  } catch (const json::exception& e) {
    throw std::invalid_argument(e.what());
  }
}

}  // namespace paddock::hal
