// autonomy/log/foxglove.h: the messages' JSON text written without a tree
// (JsonWriter, and the PointCloud's base64 spliced in) against what
// nlohmann's json::dump() makes of the same values.
#include "autonomy/log/foxglove.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace {

using namespace paddock;
using namespace paddock::log::foxglove;

std::string written(double v) {
  std::string s;
  JsonWriter(s).number(v);
  return s;
}

// the layouts of json::dump(): whole numbers with ".0" up to 1e15, no
// exponent down to 1e-5, else d.ddde+XX; zero's sign; no number for NaN
TEST(JsonWriter, NumbersAreLaidOutAsDumpLaysThemOut) {
  for (const double v : {0.0, -0.0, 1.0, -1.0, 0.5, 0.1, 2.5e-5, 1e-4, 1e-5, 1.5e-5, 123.456, -98765.4321, 1e15, 1e16,
                         1.5e16, 999999999999999.0, 1e300, -4.9e-324, 6.02214076e23, 0.325, 0.2,
                         std::numeric_limits<double>::max(), std::numeric_limits<double>::min()}) {
    EXPECT_EQ(written(v), json(v).dump()) << v;
  }
  EXPECT_EQ(written(std::nan("")), "null");
  EXPECT_EQ(written(std::numeric_limits<double>::infinity()), "null");
}

// any double reads back as itself, in dump()'s layout (grisu2's digits are
// not always the shortest: then the two texts differ in the last digit,
// both the same double)
TEST(JsonWriter, EveryNumberReadsBackAsItself) {
  std::mt19937_64 rng(5);
  for (int i = 0; i < 200000; ++i) {
    std::uint64_t bits = rng();
    double v;
    std::memcpy(&v, &bits, sizeof v);
    if (!std::isfinite(v)) continue;
    const std::string s = written(v);
    const double back = json::parse(s).get<double>();
    ASSERT_EQ(std::memcmp(&back, &v, sizeof v), 0) << s;
    const std::string d = json(v).dump();
    ASSERT_EQ(s.find('e') == std::string::npos, d.find('e') == std::string::npos) << s << " " << d;
    ASSERT_EQ(s.find('.') == std::string::npos, d.find('.') == std::string::npos) << s << " " << d;
  }
}

TEST(JsonWriter, ObjectsArraysAndStringsAsDumpWritesThem) {
  std::string s;
  JsonWriter(s)
      .begin_object()
      .key("a").begin_array().integer(-3).boolean(true).begin_object().end_object().begin_array().end_array().end_array()
      .key("b").string("quote \" backslash \\ tab \t bell \x07")
      .key("c").integer(std::numeric_limits<std::int64_t>::min())
      .end_object();
  const json j = {{"a", {-3, true, json::object(), json::array()}},
                  {"b", "quote \" backslash \\ tab \t bell \x07"},
                  {"c", std::numeric_limits<std::int64_t>::min()}};
  EXPECT_EQ(s, j.dump());
}

TEST(Foxglove, MessagesAreTheirSchemasValues) {
  std::string s;
  pose_in_frame(-1'500'000'000, "map", 1.25, -2.5, 0.3, s);
  EXPECT_EQ(s, json({{"timestamp", stamp(-1'500'000'000)}, {"frame_id", "map"}, {"pose", pose(1.25, -2.5, 0.0, 0.3)}})
                   .dump());
  transform(7, "base", "lidar", 1.0, 0.0, 0.6, 0.0, 0.05, s);
  EXPECT_EQ(s, json({{"timestamp", stamp(7)},
                     {"parent_frame_id", "base"},
                     {"child_frame_id", "lidar"},
                     {"translation", position(1.0, 0.0, 0.6)},
                     {"rotation", rotation(0.0, 0.05)}})
                   .dump());
  const std::vector<Cone> cones = {{{1.0, 2.0}, ConeColor::Blue}, {{-3.5, 0.25}, ConeColor::BigOrange}};
  cones_update(cones, 2'000'000'001, "map_cones", s);
  const json j = json::parse(s);
  ASSERT_EQ(j.at("entities").size(), 1u);
  const json& e = j.at("entities")[0];
  EXPECT_EQ(e.at("id"), "map_cones");
  EXPECT_EQ(e.at("timestamp"), stamp(2'000'000'001));
  ASSERT_EQ(e.at("cylinders").size(), 2u);
  EXPECT_EQ(e.at("cylinders")[1].at("pose"), pose(-3.5, 0.25, 0.5 * 0.505, 0.0));
  EXPECT_EQ(e.at("cylinders")[0].at("color"), rgba(0.1, 0.3, 1.0));
  EXPECT_EQ(j.dump(), s);  // keys in dump()'s order
}

TEST(Foxglove, APointCloudsDataIsItsFloatsInBase64) {
  const std::vector<float> xyzi = {1.0f, -2.0f, 0.5f, 0.25f, 3.0f, 4.0f, -5.0f, 1.0f};
  std::string s = "left over";
  point_cloud(42, "lidar", xyzi.data(), 2, s);
  const json j = json::parse(s);
  EXPECT_EQ(j.dump(), s);  // the text dump() gives
  const std::string& data = j.at("data").get_ref<const std::string&>();
  EXPECT_EQ(data, base64(reinterpret_cast<const std::uint8_t*>(xyzi.data()), xyzi.size() * sizeof(float)));
  EXPECT_EQ(j.at("point_stride"), 16);
  EXPECT_EQ(base64(reinterpret_cast<const std::uint8_t*>("foobar"), 6), "Zm9vYmFy");
  EXPECT_EQ(base64(reinterpret_cast<const std::uint8_t*>("fooba"), 5), "Zm9vYmE=");
  EXPECT_EQ(base64(reinterpret_cast<const std::uint8_t*>("foob"), 4), "Zm9vYg==");
}

}  // namespace
