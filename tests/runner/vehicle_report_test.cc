// paddock report vehicle against independent truths, on the default car with
// fields changed: without aero the skidpad limit agrees with the g-g-v at its
// speed and both stay under the friction bound tyre_d g; brakes too weak to
// lock stop in v^2 / (2 F / m). Where
// rotating wheels would matter (a model whose effective mass is a little
// above m) the tolerance is 3 % on the side they push to
#include "sim/runner/vehicle_report.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "sim/runner/files.h"
#include "sim/runner/scenario.h"

namespace paddock::runner {
namespace {

namespace fs = std::filesystem;

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
  // 600 N: 0.32 g, far below what the tyres can take; nothing else slows the car, and the brake acts at once
  const std::string path =
      car_file("weak_brakes", "brake_force_max = 600\nc_drag = 0\ncr0 = 0\nbrake_time_constant = 0\n");
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

}  // namespace
}  // namespace paddock::runner
