// the HAL messages no wire carries, as JSON: every number back to the bit
// (the car binary's stack must see what an in-process one sees), +infinity
// through null, and a message that is no paddock JSON refused with its reason
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <variant>

#include "autonomy/hal/json.h"

namespace paddock::hal {
namespace {

SensorMessage back(const SensorMessage& m) {
  const std::optional<std::string> j = to_json(m);
  EXPECT_TRUE(j);
  return message_from_json(j->data(), j->size());
}

TEST(HalJson, EveryNumberComesBackToTheBit) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1e3, 1e3);
  for (int k = 0; k < 200; ++k) {
    CameraDetections d{static_cast<TimeNs>(rng() >> 2), 1280, 720, {}};
    for (int i = 0; i < 20; ++i)
      d.boxes.push_back({u(rng), u(rng) * 1e-9, u(rng), std::nextafter(1.0, 2.0),
                         static_cast<ConeColor>(rng() % 5), std::ldexp(u(rng), -1060)});
    const auto r = std::get<CameraDetections>(back(d));
    EXPECT_EQ(r.stamp, d.stamp);
    EXPECT_EQ(r.width, 1280);
    ASSERT_EQ(r.boxes.size(), d.boxes.size());
    for (std::size_t i = 0; i < d.boxes.size(); ++i) {
      EXPECT_EQ(std::memcmp(&r.boxes[i].x_min, &d.boxes[i].x_min, 4 * sizeof(double)), 0);
      EXPECT_EQ(r.boxes[i].color, d.boxes[i].color);
      EXPECT_EQ(std::memcmp(&r.boxes[i].confidence, &d.boxes[i].confidence, sizeof(double)), 0);  // subnormal too
    }
  }
  ConeDetections c;
  c.stamp = 42;
  c.cones = {{{1.0 / 3.0, -2.0 / 7.0}, ConeColor::BigOrange, true}};
  c.free_range = {1.5f, std::numeric_limits<float>::infinity(), 1.0f / 3.0f};
  const auto rc = std::get<ConeDetections>(back(c));
  EXPECT_EQ(rc.cones[0].position.x, c.cones[0].position.x);
  EXPECT_EQ(rc.cones[0].position.y, c.cones[0].position.y);
  EXPECT_TRUE(rc.cones[0].colour_from_camera);
  ASSERT_EQ(rc.free_range.size(), 3u);
  EXPECT_EQ(rc.free_range[0], 1.5f);
  EXPECT_TRUE(std::isinf(rc.free_range[1]));
  EXPECT_EQ(rc.free_range[2], 1.0f / 3.0f);
  const StateEstimate s{7, {0.1, 0.2, 0.3}, 1.0 / 3.0, -1e-300, 2.5};
  const auto rs = std::get<StateEstimate>(back(s));
  EXPECT_EQ(rs.pose.x, 0.1);
  EXPECT_EQ(rs.vx, 1.0 / 3.0);
  EXPECT_EQ(rs.vy, -1e-300);
  // a wire carries these: no JSON
  EXPECT_FALSE(to_json(Imu{}));
  EXPECT_FALSE(to_json(LidarScan{}));
}

std::string refusal(const std::string& text) {
  try {
    message_from_json(text.data(), text.size());
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  ADD_FAILURE() << "accepted: " << text;
  return "";
}

TEST(HalJson, ABadMessageIsRefusedWithItsReason) {
  EXPECT_NE(refusal("{\"type\": ").find("no JSON"), std::string::npos);
  EXPECT_NE(refusal("[1, 2]").find("expected a JSON object"), std::string::npos);
  EXPECT_NE(refusal("{\"stamp\": 1}").find("type"), std::string::npos);
  EXPECT_NE(refusal("{\"type\": \"lidar_scan\", \"stamp\": 1}").find("\"lidar_scan\" is none of"), std::string::npos);
  EXPECT_NE(refusal(R"({"type": "state_estimate", "stamp": -1, "x": 0, "y": 0, "yaw": 0, "vx": 0, "vy": 0, "yaw_rate": 0})")
                .find("stamp -1 is before 0"),
            std::string::npos);
  EXPECT_NE(refusal(R"({"type": "camera_detections", "stamp": 1, "width": 2, "height": 2, "boxes": [{"x_min": 0, "y_min": 0, "x_max": 1, "y_max": 1, "color": 9, "confidence": 1}]})")
                .find("color 9"),
            std::string::npos);
  EXPECT_NE(refusal(R"({"type": "state_estimate", "stamp": 1, "x": "a"})").find("type must be number"), std::string::npos);
}

}  // namespace
}  // namespace paddock::hal
