// scenario compilation: unknown keys and bad values are file:line errors,
// overrides go through the same checks, and the resolved file reads back the same
#include "sim/runner/scenario.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "sim/runner/files.h"
#include "sim/runner/ini.h"
#include "sim/runner/report.h"
#include "sim/runner/schema.h"
#include "sim/runner/simulation.h"

namespace paddock::runner {
namespace {

namespace fs = std::filesystem;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

const std::string kRoot = PADDOCK_SOURCE_DIR;
const std::string kDefault = kRoot + "/scenarios/fsg_2023_trackdrive.ini";

// a scenario file in scenarios/ (so that its includes resolve) for one test
class ScenarioFile : public ::testing::Test {
 protected:
  void TearDown() override {
    for (const auto& p : written_) fs::remove(p);
  }
  std::string write(const std::string& text) {
    const std::string p = kRoot + "/scenarios/_test_" +
                          ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".ini";
    std::ofstream(p) << text;
    written_.push_back(p);
    return p;
  }
  std::string error_of(const std::string& path, const std::vector<std::string>& overrides = {}) {
    try {
      load_scenario(path, overrides);
    } catch (const UserError& e) {
      return e.what();
    }
    return "(no error)";
  }
  std::vector<std::string> written_;
};

const char* kHead =
    "include = vehicles/default.ini\n"
    "[scenario]\n"
    "track = ../tracks/fsg_2023.csv\n";

TEST(Scenario, DefaultLoadsWithTheVehicleFile) {
  const Scenario s = load_scenario(kDefault);
  EXPECT_EQ(s.name, "fsg_2023_trackdrive");
  EXPECT_EQ(s.scenario.event, events::EventKind::Trackdrive);
  EXPECT_EQ(s.vehicle.mass, 210.0);  // scenarios/vehicles/default.ini
  EXPECT_EQ(s.vehicle.accumulator_power_max, 80000.0);
  EXPECT_TRUE(fs::exists(s.track_path)) << s.track_path;
  // it races (racing.ini): the Stanley law on the car's envelope
  EXPECT_EQ(s.control.lateral, control::LateralMode::Stanley);
  EXPECT_EQ(s.planning.line, planning::PathPlannerParams::MinCurvature);
}

TEST_F(ScenarioFile, UnknownKeyNamesFileLineAndTheKnownKeys) {
  const auto p = write(std::string(kHead) + "[control.stanley]\nk = 2\nk_sof = 2\n");
  const auto msg = error_of(p);
  EXPECT_THAT(msg, HasSubstr(p + ":6: unknown key 'k_sof' in [control.stanley]; expected one of: "));
  EXPECT_THAT(msg, HasSubstr("k_soft"));
}

TEST_F(ScenarioFile, UnknownSection) {
  const auto p = write(std::string(kHead) + "[contrl]\nx = 1\n");
  EXPECT_THAT(error_of(p), HasSubstr(p + ":5: unknown section [contrl]"));
}

TEST_F(ScenarioFile, BadValuesNameWhatWasExpected) {
  EXPECT_THAT(error_of(write(std::string(kHead) + "[control.stanley]\nk = fast\n")),
              HasSubstr(":5: [control.stanley] k = 'fast' is not a number; expected a number in 1/s"));
  EXPECT_THAT(error_of(write(std::string(kHead) + "[control]\nlateral = mpc\n")),
              HasSubstr(":5: [control] lateral = 'mpc' is not known; expected one of: combined, stanley, pure_pursuit"));
  EXPECT_THAT(error_of(write(std::string(kHead) + "[control.combined]\nk_min = 1.5\n")),
              HasSubstr(":5: [control.combined] k_min = 1.5 is out of range; expected in [0, 1]"));
  EXPECT_THAT(error_of(write(std::string(kHead) + "[vehicle]\nmass = 190 lb\n")),
              HasSubstr(":5: [vehicle] mass = '190 lb': unit 'lb' does not fit; expected a number in kg"));
  EXPECT_THAT(error_of(write(std::string(kHead) + "[sim]\nphysics_rate = 1000.5\n")),
              HasSubstr(":5: [sim] physics_rate = '1000.5' is not an integer"));
}

TEST_F(ScenarioFile, UnitsConvertToSI) {
  const auto p = write(std::string(kHead) + "[vehicle]\nsteering_max = 30 deg\n[planning.reference.profile]\nv_max = 72 km/h\n");
  const Scenario s = load_scenario(p);
  EXPECT_NEAR(s.vehicle.steering_max, 30.0 * M_PI / 180.0, 1e-15);
  EXPECT_NEAR(s.planning.reference.profile.v_max, 20.0, 1e-12);
}

TEST_F(ScenarioFile, MissingVehicleKeysAreNamed) {
  const auto p = write("[scenario]\ntrack = ../tracks/fsg_2023.csv\n");
  EXPECT_THAT(error_of(p), HasSubstr("[vehicle] mass is not set (kg); include a vehicle file"));
}

TEST_F(ScenarioFile, MissingTrackKeyIsNamed) {
  const auto p = write("include = vehicles/default.ini\n");
  EXPECT_THAT(error_of(p), HasSubstr("[scenario] track is not set"));
}

// the error of loading the default scenario with these overrides ("(no error)": none)
std::string override_error(const std::vector<std::string>& overrides) {
  try {
    load_scenario(kDefault, overrides);
  } catch (const UserError& e) {
    return std::string(e.what());
  }
  return std::string("(no error)");
}

TEST(Scenario, OverridesWinAndAreChecked) {
  const Scenario s = load_scenario(kDefault, {"control.lateral=stanley", "scenario.seed = 7"});
  EXPECT_EQ(s.control.lateral, control::LateralMode::Stanley);
  EXPECT_EQ(s.scenario.seed, 7u);
  EXPECT_THAT(override_error({"control.lateral=mpc"}), HasSubstr("--set:1: [control] lateral = 'mpc' is not known"));
  EXPECT_THAT(override_error({"seed=3", }), HasSubstr("--set seed=3: expected section.key=value"));
  EXPECT_THAT(override_error({"scenario.seed=1", "control.nokey=1"}), HasSubstr("--set:2: unknown key 'nokey' in [control]"));
}

// every sensor samples a whole number of physics steps apart: a physics
// rate its rate does not divide is refused, naming both (before, 500 Hz
// physics silently sampled the 200 Hz IMU every 3 steps, at 166.7 Hz)
TEST(Scenario, ASensorRateThePhysicsRateDoesNotDivideIsRefused) {
  EXPECT_THAT(override_error({"sim.physics_rate=500"}),
              HasSubstr("physics_rate (500 Hz) must be a whole multiple of [imu] rate (200 Hz): it would be sampled "
                        "every 3 steps, at 166.7 Hz"));
  EXPECT_THAT(override_error({"wheel_speeds.rate=300"}), HasSubstr("must be a whole multiple of [wheel_speeds] rate (300 Hz)"));
  EXPECT_THAT(override_error({"steering_sensor.rate=3000"}),
              HasSubstr("[steering_sensor] rate (3000 Hz): it would be sampled every step, at 1000 Hz"));
  EXPECT_THAT(override_error({"cone_sensor.rate=7"}), HasSubstr("[cone_sensor] rate (7 Hz)"));
  // rates that divide it: each sensor every whole number of steps
  EXPECT_EQ(override_error({"sim.physics_rate=400"}), "(no error)");
  EXPECT_EQ(override_error({"cone_sensor.rate=12.5", "imu.rate=250"}), "(no error)");
  const SimModel m = compile_model(load_scenario(kDefault, {"sim.physics_rate=400"}),
                                   world::build_track(load_track_file(load_scenario(kDefault).track_path)));
  EXPECT_EQ(m.every.imu, 2);
  EXPECT_EQ(m.every.wheel_speeds, 4);
}

TEST(Scenario, DetectorKeysSetTheSimulatedDetectorNode) {
  // [detector] is the simulator's detector node (sim/sensors), not the stack's
  const Scenario s = load_scenario(kDefault, {"detector.p_miss_near=0.1", "detector.box_jitter=0.05"});
  EXPECT_EQ(s.detector.p_miss_near, 0.1);
  EXPECT_EQ(s.detector.box_jitter, 0.05);
  try {
    load_scenario(kDefault, {"detector.range_full=40"});  // beyond range_max
    ADD_FAILURE() << "no error";
  } catch (const UserError& e) {
    EXPECT_THAT(e.what(), HasSubstr("[detector] range_max must be > range_full"));
  }
}

TEST(Scenario, ResolvedFileReadsBackToTheSameScenario) {
  Scenario a = load_scenario(kDefault, {"control.stanley.k=3.25", "vehicle.steering_max=25 deg"});
  const std::string text = resolved_ini(a);
  // every key is written, defaults included, in its section; an unset
  // optional one ([expect], a fault's time) as a comment
  for (const Key& k : scenario_keys(a)) {
    if (k.section == "expect") continue;
    const std::string v = k.get();
    const bool unset = v.empty() && k.expected != "text";
    EXPECT_THAT(text, HasSubstr(unset ? "\n; " + k.name + " =  ; (unset)" : "\n" + k.name + " = " + v)) << k.path();
  }
  const std::string p = (fs::temp_directory_path() / "paddock_resolved_test.ini").string();
  write_file_atomic(p, text);
  const Scenario b = load_scenario(p);
  // the same text apart from the "; from" line
  const std::string again = resolved_ini(b);
  EXPECT_EQ(again.substr(again.find("\n[scenario]")), text.substr(text.find("\n[scenario]")));
  EXPECT_EQ(b.control.stanley.k, 3.25);
  EXPECT_EQ(b.vehicle.steering_max, a.vehicle.steering_max);  // bit-exact through the text
  fs::remove(p);
}

TEST_F(ScenarioFile, AVehicleOutsideThePhysicalRangeOrTooLargeAStepIsRejectedAtLoad) {
  // values that used to pass and then drove the state to NaN (or passed in silence)
  EXPECT_THAT(error_of(write(std::string(kHead) + "[vehicle]\nmass = 0.001\n")),
              HasSubstr(":5: [vehicle] mass = 0.001 is out of range; expected in [50, 2000] kg"));
  EXPECT_THAT(error_of(write(std::string(kHead) + "[vehicle]\nmass = 1e308\n")), HasSubstr("[vehicle] mass = 1e308 is out of range"));
  EXPECT_THAT(error_of(write(std::string(kHead) + "[vehicle]\ninertia_z = 1e-300\n")), HasSubstr("[vehicle] inertia_z"));
  EXPECT_THAT(error_of(write(std::string(kHead) + "[vehicle]\ntyre_d = 1e6\n")), HasSubstr("[vehicle] tyre_d"));
  // the default car's fastest mode: the wheels' low-speed damping, ~454 1/s,
  // so 10 and 100 Hz are unstable and 200 Hz is not
  EXPECT_THAT(error_of(write(std::string(kHead) + "[sim]\nphysics_rate = 10\ncontrol_rate = 10\nlog_rate = 10\n")),
              HasSubstr("[sim] physics_rate must be at least 182 Hz for this vehicle"));
  EXPECT_THAT(error_of(write(std::string(kHead) + "[sim]\nphysics_rate = 100\n")), HasSubstr("at least 182 Hz"));
  EXPECT_EQ(error_of(write(std::string(kHead) + "[sim]\nphysics_rate = 200\n")), "(no error)");
}

TEST(Scenario, TheStableStepLimitIsTheCarsFastestMode) {
  // recomputed by hand for the default car, whose fastest mode is a rear
  // wheel's spin against the tyre's low-speed damper (0.3 of critical for a
  // quarter of the car on the slip stiffness C_k / sigma_x, C_k = B_x C D_x
  // L(Fz) Fz at the static load): lambda = c r^2 / I
  const Scenario s = load_scenario(kDefault);
  const vehicle::VehicleParams& v = s.vehicle;
  const double fz = 0.5 * v.mass * kGravity * v.lf / (v.lf + v.lr);
  const double c_kappa = v.tyre_bx * v.tyre_c * v.tyre_dx * vehicle::load_factor(v, fz) * fz;
  const double damper = 0.3 * 2.0 * std::sqrt(c_kappa / v.relaxation_length_x * 0.25 * v.mass);
  const double lambda = damper * v.wheel_radius * v.wheel_radius / (v.wheel_inertia + v.driveline_inertia);
  EXPECT_NEAR(vehicle::stable_step_limit(v), 2.5 / lambda, 1e-12);
  EXPECT_NEAR(vehicle::stable_step_limit(v), 0.0055, 0.0003);
}

TEST_F(ScenarioFile, LioWithoutTheLidarSaysWhatItNeeds) {
  EXPECT_THAT(error_of(write(std::string(kHead) + "[autonomy]\nperception = ground_truth\nslam = lio\n")),
              HasSubstr(".ini: [autonomy] slam = lio or lio_graph needs the LiDAR's scans: autonomy.perception = lidar or lidar_camera"));
}

TEST_F(ScenarioFile, AnOldKeyNamesItsNewPlace) {
  EXPECT_THAT(error_of(write(std::string(kHead) + "[control]\nstanley_k = 2\n")),
              HasSubstr(":5: unknown key 'stanley_k' in [control]; it is now [control.stanley] k"));
  EXPECT_THAT(error_of(write(std::string(kHead) + "[slam]\nmin_observations = 3\n")),
              HasSubstr(":5: unknown key 'min_observations' in [slam]; it is now [cone_map] min_observations"));
}

TEST(Scenario, SectionsAndKeysFollowTheStructPaths) {
  const Scenario s = load_scenario(kDefault, {"perception.lidar.clustering.tolerance=0.35", "control.pure_pursuit.L_min=3",
                                              "planning.search.weight_colour=2.5", "perception.lidar.ground.max_slope=0.2"});
  EXPECT_EQ(s.perception.lidar.clustering.tolerance, 0.35);
  EXPECT_EQ(s.control.pure_pursuit.L_min, 3.0);
  EXPECT_EQ(s.planning.search.weight_colour, 2.5);
  EXPECT_EQ(s.perception.lidar.ground.max_slope, 0.2);
  // and reach the stack
  EXPECT_EQ(stack_params(s).perception.lidar.clustering.tolerance, 0.35);
  EXPECT_EQ(stack_params(s).planning.search.weight_colour, 2.5);
}

// values other than k's own that its declaration allows (a rule tying it
// to another field may still refuse some)
std::vector<std::string> other_values(const Key& k) {
  const std::string now = k.get();
  std::vector<std::string> out;
  // a file name: the [hal] files shipped in scenarios/sensors
  if (k.expected == "text") {
    if (k.path() == "hal.dbc") out.push_back(kRoot + "/scenarios/sensors/paddock.dbc");
    if (k.path() == "hal.lidar_metadata") out.push_back(kRoot + "/scenarios/sensors/os2_32.json");
    return out;
  }
  if (k.expected == "true or false") return {now == "true" ? "false" : "true"};
  if (k.expected.rfind("one of: ", 0) == 0) {
    std::string rest = k.expected.substr(8);
    for (std::size_t c; (c = rest.find(", ")) != std::string::npos; rest = rest.substr(c + 2)) {
      if (rest.substr(0, c) != now) out.push_back(rest.substr(0, c));
    }
    if (rest != now) out.push_back(rest);
    return out;
  }
  const double v = now.empty() ? 0.0 : std::stod(now);
  for (double t : {v * 1.25, v * 0.8, v + 1.0, v - 1.0, v + 0.01, v - 0.01, 0.5, 1.0, 0.0}) {
    if (k.integer) t = std::round(t);
    if (t != v && k.bounds.contains(t)) out.push_back(k.integer ? std::to_string(static_cast<long>(t)) : params::number(t));
  }
  return out;
}

TEST(Scenario, OneParameterOfEveryParamsStructIsSetByItsStructPath) {
  Scenario defaults = load_scenario(kDefault);
  const std::vector<Key> keys = scenario_keys(defaults);
  int sections_set = 0;
  for (const SectionDoc& section : scenario_sections()) {
    bool has_keys = false, set = false;
    std::string tried;
    for (const Key& k : keys) {
      if (k.section != section.section || set) continue;
      has_keys = true;
      for (const std::string& value : other_values(k)) {
        if (set) break;
        const std::string override = k.path() + "=" + value;
        tried += " " + override;
        Scenario s;
        try {
          s = load_scenario(kDefault, {override});
        } catch (const UserError&) {
          continue;  // a rule tying it to another field: try another value or key
        }
        // the resolved scenario carries it in its section
        const std::vector<IniEntry> entries = parse_ini_text(resolved_ini(s), "resolved", kRoot + "/scenarios");
        for (const IniEntry& e : entries) {
          if (e.section != k.section || e.key != k.name) continue;
          if (k.expected.rfind("one of", 0) == 0 || k.expected == "true or false" || k.expected == "text")
            EXPECT_EQ(e.value, value) << override;
          else EXPECT_EQ(std::stod(e.value), std::stod(value)) << override;
          set = true;
        }
        EXPECT_TRUE(set) << override << " is not in the resolved scenario";
      }
    }
    if (!has_keys) continue;  // a struct of structs: its members are sections of their own
    EXPECT_TRUE(set) << "no key of [" << section.section << "] could be set; tried:" << tried;
    sections_set += set ? 1 : 0;
  }
  // every module's Params: the vehicle, the world, the sensors, perception's
  // stages, planning's, control's, the mission's, the sim's
  EXPECT_GE(sections_set, 35);
}

TEST(Scenario, TheReadmesTableOfKeysIsCurrent) {
  const std::string readme = read_file(kRoot + "/README.md");
  const std::string begin = "<!-- keys: generated by ./paddock keys -->\n", end = "<!-- keys end -->";
  const auto a = readme.find(begin), b = readme.find(end);
  ASSERT_NE(a, std::string::npos);
  ASSERT_NE(b, std::string::npos);
  // the first line that differs, to say which key is stale
  std::istringstream in_readme(readme.substr(a + begin.size(), b - a - begin.size())), in_keys("\n" + keys_markdown() + "\n");
  std::string x, y;
  int line = 0;
  bool same = true;
  while (same) {
    const bool more_x = static_cast<bool>(std::getline(in_readme, x)), more_y = static_cast<bool>(std::getline(in_keys, y));
    ++line;
    if (!more_x && !more_y) break;
    same = more_x == more_y && x == y;
  }
  EXPECT_TRUE(same) << "line " << line << " of the README's table is\n  " << x << "\nbut ./paddock keys prints\n  " << y
                    << "\nrun ./paddock keys and paste its table into the README between the markers";
}

// ---- a vehicle file on its own (paddock report vehicle) ----

// a vehicle file in a scratch folder; `text` may include the default car by its absolute path
std::string vehicle_file(const std::string& name, const std::string& text) {
  const fs::path d = fs::temp_directory_path() / "paddock_vehicle_file_test";
  fs::create_directories(d);
  const std::string p = (d / (name + ".ini")).string();
  std::ofstream(p) << text;
  return p;
}

std::string vehicle_error(const std::string& path) {
  try {
    load_vehicle_file(path);
  } catch (const UserError& e) {
    return e.what();
  }
  return "(no error)";
}

const std::string kIncludeCar = "include = " + kRoot + "/scenarios/vehicles/default.ini\n";

TEST(VehicleFile, TheDefaultCarIsTheScenariosCar) {
  Scenario from_file, from_scenario = load_scenario(kDefault);
  from_file.vehicle = load_vehicle_file(kRoot + "/scenarios/vehicles/default.ini");
  const std::vector<Key> a = scenario_keys(from_file), b = scenario_keys(from_scenario);
  int compared = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].section != "vehicle") continue;
    EXPECT_EQ(a[i].get(), b[i].get()) << a[i].name;
    ++compared;
  }
  EXPECT_EQ(compared, static_cast<int>(params::field_paths(vehicle::VehicleParams{}).size()));
}

TEST(VehicleFile, OverridesAfterAnIncludeWin) {
  const auto p = vehicle_file("override", kIncludeCar + "[vehicle]\nc_drag = 0\nmass = 250 ; heavier\n");
  const vehicle::VehicleParams v = load_vehicle_file(p);
  EXPECT_EQ(v.c_drag, 0.0);
  EXPECT_EQ(v.mass, 250.0);
}

TEST(VehicleFile, BadInputIsAFileLineErrorLikeAScenarios) {
  const auto unknown = vehicle_file("unknown", kIncludeCar + "[vehicle]\nmass = 190\nmas = 3\n");
  EXPECT_THAT(vehicle_error(unknown), HasSubstr(unknown + ":4: unknown key 'mas' in [vehicle]; expected one of: mass, "));
  const auto section = vehicle_file("section", kIncludeCar + "[control]\nlateral = stanley\n");
  EXPECT_THAT(vehicle_error(section), HasSubstr(section + ":3: unknown section [control]; expected one of: [vehicle]"));
  const auto number = vehicle_file("number", kIncludeCar + "[vehicle]\ntyre_d = grippy\n");
  EXPECT_THAT(vehicle_error(number), HasSubstr(number + ":3: [vehicle] tyre_d = 'grippy' is not a number"));
  const auto range = vehicle_file("range", kIncludeCar + "[vehicle]\nmass = 0.001\n");
  EXPECT_THAT(vehicle_error(range), HasSubstr(range + ":3: [vehicle] mass = 0.001 is out of range; expected in [50, 2000] kg"));
  const auto unset = vehicle_file("unset", "[vehicle]\nmass = 190\n");
  EXPECT_THAT(vehicle_error(unset), HasSubstr(unset + ": [vehicle] inertia_z is not set (kg m^2)"));
  EXPECT_THAT(vehicle_error(kRoot + "/scenarios/vehicles/no_such_car.ini"), HasSubstr("no_such_car.ini: cannot open"));
}

TEST(VehicleFile, ACarTheDefaultStepCannotIntegrateIsRejected) {
  // exactly the cars whose stable step (the model's own figure) is under the
  // default 1 ms; the light, stiff and grippy one is, for the single-track model
  struct Candidate {
    const char* name;
    const char* lines;
    void (*set)(vehicle::VehicleParams&);
  };
  const Candidate candidates[] = {
      {"as_is", "", [](vehicle::VehicleParams&) {}},
      {"stiff", "mass = 50\ninertia_z = 5\ntyre_b = 50\ntyre_d = 3\n",
       [](vehicle::VehicleParams& v) { v.mass = 50, v.inertia_z = 5, v.tyre_b = 50, v.tyre_d = 3; }},
      {"heavy", "mass = 2000\ninertia_z = 3000\nwheel_radius = 0.6\n",
       [](vehicle::VehicleParams& v) { v.mass = 2000, v.inertia_z = 3000, v.wheel_radius = 0.6; }},
  };
  const vehicle::VehicleParams car = load_vehicle_file(kRoot + "/scenarios/vehicles/default.ini");
  for (const Candidate& c : candidates) {
    vehicle::VehicleParams v = car;
    c.set(v);
    const auto p = vehicle_file(c.name, kIncludeCar + "[vehicle]\n" + c.lines);
    if (vehicle::stable_step_limit(v) < 1e-3) {
      EXPECT_THAT(vehicle_error(p), HasSubstr(p + ": [vehicle] at the default physics rate: sim.physics_rate must be at least"));
    } else {
      EXPECT_EQ(vehicle_error(p), "(no error)") << c.name;
    }
  }
}

// [expect] ate_max_max holds the estimate's worst moment, not only its
// RMS: the run's largest ATE against the bound, and with the stack in the
// car binary (where the estimate stays) a failure that says it was not
// measured
TEST(Expectations, AteMaxIsTheEstimatesWorstMoment) {
  RunResult r;
  r.slam.ate_rms = 0.05;
  r.slam.ate_max = 0.5;
  Expectations e;
  e.ate_max_max = 0.6;
  EXPECT_TRUE(check_expectations(e, r).empty());
  e.ate_max_max = 0.4;
  EXPECT_THAT(check_expectations(e, r), ElementsAre("ATE max: expected at most 0.400 m, got 0.500 m"));
  r.stack_remote = true;
  r.slam.ate_max = 0.0;
  EXPECT_THAT(check_expectations(e, r),
              ElementsAre("ATE max: not measured: the stack ran in the car binary (transport = udp)"));
}

}  // namespace
}  // namespace paddock::runner
