// paddock report vehicle against independent truths, on the default car with
// fields changed: without aero the skidpad limit agrees with the g-g-v at its
// speed and both stay under the friction bound tyre_d g; brakes too weak to
// lock stop in v^2 / (2 F / m); and the command's errors and files. Where
// rotating wheels would matter (a model whose effective mass is a little
// above m) the tolerance is 3 % on the side they push to
#include "sim/runner/vehicle_report.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "render/figures.h"
#include "sim/runner/files.h"
#include "sim/runner/scenario.h"
#include "tests/runner/run_paddock.h"

namespace paddock::runner {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

const std::string kRoot = PADDOCK_SOURCE_DIR;

std::string scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / "paddock_vehicle_report_test";
  fs::create_directories(d);
  return (d / name).string();
}

// the default car with some [vehicle] lines added after it, as a file
std::string car_file(const std::string& name, const std::string& changes) {
  const std::string p = scratch(name + ".ini");
  write_file_atomic(p, "include = " + kRoot + "/scenarios/vehicles/default.ini\n[vehicle]\n" + changes);
  return p;
}

TEST(VehicleReport, WithoutAeroTheSkidpadAgreesWithTheGgvAndStaysUnderTheFriction) {
  const std::string path = car_file("no_aero", "c_down = 0\nc_drag = 0\n");
  const vehicle::VehicleParams p = load_vehicle_file(path);
  const VehicleReport r = vehicle_report(p, path);
  // no downforce: the tyres' normal loads add up to m g, their forces to at most tyre_d m g
  const double friction = p.tyre_d * kGravity;
  ASSERT_TRUE(r.skidpad.held);
  EXPECT_NEAR(r.skidpad.lateral, r.skidpad.speed * r.skidpad.speed / kSkidpadRadius, 1e-9);
  EXPECT_NEAR(r.skidpad.lap_time, 2.0 * kPi * kSkidpadRadius / r.skidpad.speed, 1e-9);
  EXPECT_LE(r.skidpad.radius_error_max, 0.25);
  EXPECT_LT(r.skidpad.lateral, friction);
  // the driver finds the limit, not a fraction of it
  EXPECT_GT(r.skidpad.lateral, 0.85 * friction);
  ASSERT_FALSE(r.ggv.empty());
  for (const GgvRow& row : r.ggv) EXPECT_LT(row.lateral, friction) << row.speed << " m/s";
  // the g-g-v's steady lateral at the speed nearest the skidpad's is the
  // skidpad's (at 5 m/s the circle is under 2 m wide and the steered front
  // tyres' drag takes grip, so the lowest speed is not the comparison)
  const GgvRow* nearest = &r.ggv.front();
  for (const GgvRow& row : r.ggv) {
    if (std::abs(row.speed - r.skidpad.speed) < std::abs(nearest->speed - r.skidpad.speed)) nearest = &row;
  }
  EXPECT_NEAR(nearest->lateral, r.skidpad.lateral, 0.03 * r.skidpad.lateral) << "at " << nearest->speed << " m/s";
}

TEST(VehicleReport, BrakesTooWeakToLockStopInVSquaredOverTwiceTheirDeceleration) {
  // 2000 N on 800 kg: 0.25 g, far below what the tyres can take; nothing else
  // slows the car, and the brake acts at once. (The weight keeps what spinning
  // wheels and motors add to the mass braked under 3 %)
  const std::string path = car_file("weak_brakes",
                                    "mass = 800\ninertia_z = 400\nbrake_force_max = 2000\n"
                                    "c_drag = 0\ncr0 = 0\nbrake_time_constant = 0\n");
  const vehicle::VehicleParams p = load_vehicle_file(path);
  const VehicleReport r = vehicle_report(p, path);
  const double a = p.brake_force_max / p.mass, v0 = kBrakingSpeed;
  const double distance = v0 * v0 / (2.0 * a), time = v0 / a;
  ASSERT_TRUE(r.full_brake.stopped);
  // rotating wheels make it up to 3 % longer; nothing makes it shorter
  EXPECT_GE(r.full_brake.distance, 0.99 * distance);
  EXPECT_LE(r.full_brake.distance, 1.03 * distance);
  EXPECT_GE(r.full_brake.time, 0.99 * time);
  EXPECT_LE(r.full_brake.time, 1.03 * time);
  EXPECT_GE(r.full_brake.mean_deceleration, a / 1.03);
  EXPECT_LE(r.full_brake.mean_deceleration, a / 0.99);
  // when nothing locks, less pedal only stops later
  EXPECT_EQ(r.best_brake.pedal, 1.0);
  EXPECT_EQ(r.best_brake.distance, r.full_brake.distance);
  // and the g-g-v's braking is F / m at every speed
  ASSERT_FALSE(r.ggv.empty());
  for (const GgvRow& row : r.ggv) {
    EXPECT_GE(row.braking, a / 1.03) << row.speed << " m/s";
    EXPECT_LE(row.braking, a / 0.99) << row.speed << " m/s";
    EXPECT_EQ(row.braking_pedal, 1.0) << row.speed << " m/s";
  }
}

using paddock::testing::Outcome;
Outcome paddock(const std::string& args) { return paddock::testing::run_paddock(args); }

TEST(ReportVehicleCli, AMissingFileIsNamedAndExits2) {
  const Outcome o = paddock("report vehicle " + scratch("no_such_car.ini") + " --out " + scratch("missing_out"));
  EXPECT_EQ(o.code, 2);
  EXPECT_THAT(o.output, HasSubstr("no_such_car.ini: cannot open"));
  EXPECT_FALSE(fs::exists(scratch("missing_out")));
}

TEST(ReportVehicleCli, BadKeysAndValuesAreFileLineErrorsAndExit2) {
  const std::string unknown = car_file("unknown_key", "mass = 190\nmas = 3\n");
  Outcome o = paddock("report vehicle " + unknown + " --out " + scratch("unknown_out"));
  EXPECT_EQ(o.code, 2);
  EXPECT_THAT(o.output, HasSubstr(unknown + ":4: unknown key 'mas' in [vehicle]"));
  const std::string range = car_file("out_of_range", "tyre_d = 7\n");
  o = paddock("report vehicle " + range + " --out " + scratch("range_out"));
  EXPECT_EQ(o.code, 2);
  EXPECT_THAT(o.output, HasSubstr(range + ":3: [vehicle] tyre_d = 7 is out of range"));
  o = paddock("report vehicle " + range + " --map-size 900");
  EXPECT_EQ(o.code, 2);
  EXPECT_THAT(o.output, HasSubstr("unknown option --map-size"));
}

// the command with its defaults (the tree's default car, runs/vehicle_default
// in the current folder) in an empty scratch folder
TEST(ReportVehicleCli, WritesTheJsonAndTheFigureOfTheStatedSize) {
  const fs::path dir = scratch("cwd");
  fs::remove_all(dir);
  fs::create_directories(dir);
  // (run_paddock starts in the test's folder: this one starts in the scratch one)
  std::string output;
  {
    const std::string command = "cd " + dir.string() + " && " + PADDOCK_BINARY + " report vehicle --chart-size 900x600";
    FILE* p = popen((command + " 2>&1").c_str(), "r");
    ASSERT_NE(p, nullptr);
    char buf[4096];
    std::size_t n;
    while ((n = fread(buf, 1, sizeof buf, p)) > 0) output.append(buf, n);
    EXPECT_EQ(pclose(p), 0) << output;
  }
  for (const char* part : {"0-75 m", "top speed", "full brake", "best pedal", "skidpad", "g-g-v", "ggv.png"}) {
    EXPECT_THAT(output, HasSubstr(part));
  }
  const fs::path out = dir / "runs/vehicle_default";
  const nlohmann::json j = nlohmann::json::parse(read_file((out / "vehicle_report.json").string()));
  EXPECT_EQ(j.at("vehicle"), kRoot + "/scenarios/vehicles/default.ini");
  const double top = j.at("top_speed").at("speed");
  EXPECT_NEAR(j.at("top_speed").at("speed_kmh").get<double>(), 3.6 * top, 1e-9);
  EXPECT_TRUE(j.at("acceleration_75m").at("reached").get<bool>());
  EXPECT_LT(j.at("acceleration_75m").at("speed").get<double>(), top);
  const auto& k = j.at("skidpad");
  EXPECT_NEAR(k.at("lap_time").get<double>(), 2.0 * kPi * kSkidpadRadius / k.at("speed").get<double>(), 1e-9);
  // the g-g-v: 5 m/s steps up to the top speed
  ASSERT_FALSE(j.at("ggv").empty());
  for (std::size_t i = 0; i < j.at("ggv").size(); ++i) {
    const auto& row = j.at("ggv")[i];
    EXPECT_EQ(row.at("speed").get<double>(), 5.0 * static_cast<double>(i + 1));
    EXPECT_NEAR(row.at("lateral_g").get<double>(), row.at("lateral").get<double>() / kGravity, 1e-12);
  }
  EXPECT_LE(j.at("ggv").back().at("speed").get<double>(), top);
  EXPECT_GT(j.at("ggv").back().at("speed").get<double>() + 5.0, std::min(top, 100.0));
  const std::string png = read_file((out / "ggv.png").string());
  const render::Image img = render::decode_png(std::vector<std::uint8_t>(png.begin(), png.end()));
  EXPECT_EQ(img.width, 900);
  EXPECT_EQ(img.height, 600);
  // written in place: nothing else left in the folder
  int files = 0;
  for (const auto& e : fs::directory_iterator(out)) {
    EXPECT_THAT(e.path().filename().string(), ::testing::AnyOf("vehicle_report.json", "ggv.png"));
    ++files;
  }
  EXPECT_EQ(files, 2);
  // the same car in this process gives the same file, byte for byte
  const vehicle::VehicleParams p = load_vehicle_file(kRoot + "/scenarios/vehicles/default.ini");
  EXPECT_EQ(read_file((out / "vehicle_report.json").string()),
            vehicle_report_json(vehicle_report(p, kRoot + "/scenarios/vehicles/default.ini")));
}

}  // namespace
}  // namespace paddock::runner
