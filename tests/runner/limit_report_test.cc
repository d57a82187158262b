// paddock report limit against closed forms (a ring circuit: the QSS lap of
// the outer circle less the clearance), against its own constraints on a
// real track (every sample within the envelope and the clearance, the
// minimum-curvature line faster than the centreline), the envelope taken
// from the vehicle report's rows, and the command's errors and files
#include "sim/runner/limit_report.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "autonomy/common/polyline.h"
#include "sim/runner/files.h"
#include "sim/runner/scenario.h"
#include "tests/runner/run_paddock.h"

namespace paddock::runner {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

const std::string kRoot = PADDOCK_SOURCE_DIR;

std::string scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / "paddock_limit_report_test";
  fs::create_directories(d);
  return (d / name).string();
}

// a flat envelope: ay, then acceleration and braking at every speed
planning::VelocityProfileParams flat_envelope(double ay, double acc, double brk) {
  planning::VelocityProfileParams e;
  e.limits = planning::VelocityProfileParams::Ggv;
  e.ggv_speed = {0.0};
  e.ggv_lateral = {ay};
  e.ggv_accel = {acc};
  e.ggv_brake = {brk};
  e.margin_lateral = e.margin_longitudinal = 1.0;
  e.turn_accel_scale = 1.0;
  e.v_max = 100.0;
  return e;
}

// a ring circuit: blue cones on r = 10 m (the left, driving anticlockwise),
// yellow on r = 16 m, about 1.5 m apart, the start on the centreline
world::TrackModel ring() {
  std::ostringstream f;
  f << "# start 13 0 " << kPi / 2.0 << "\ntag,x,y\n";
  for (const auto& [tag, r] : {std::pair{"blue", 10.0}, std::pair{"yellow", 16.0}}) {
    const int n = static_cast<int>(std::ceil(2.0 * kPi * r / 1.5));
    for (int i = 0; i < n; ++i) {
      const double a = 2.0 * kPi * i / n;
      f << tag << "," << r * std::cos(a) << "," << r * std::sin(a) << "\n";
    }
  }
  return world::build_track(world::parse_track(f.str(), "ring.csv"));
}

TEST(LimitLines, RingGivesTheQssLapOfTheOuterCircle) {
  // the least-bending lap in the ring is the circle of R = 16 - clearance;
  // at a flat 12 m/s^2 the QSS speed is sqrt(12 R) all round, the lap 2 pi R
  // / v = 2 pi sqrt(R / 12): 7.025 s at R = 15, 6.545 s on the centreline
  // (R = 13). The cones' polygons sit a few cm inside the circles.
  const world::TrackModel track = ring();
  const LimitLines l = limit_lines(track, flat_envelope(12.0, 5.0, 10.0), 1.0);
  EXPECT_NEAR(l.min_curvature.lap_time, 2.0 * kPi * std::sqrt(15.0 / 12.0), 0.005 * 7.025);
  EXPECT_NEAR(l.centreline.lap_time, 2.0 * kPi * std::sqrt(13.0 / 12.0), 0.005 * 6.545);
  EXPECT_NEAR(l.min_curvature.v_min, std::sqrt(12.0 * 15.0), 0.05);
  EXPECT_NEAR(l.min_curvature.v_max, std::sqrt(12.0 * 15.0), 0.05);
  EXPECT_NEAR(l.min_curvature.clearance_min, 1.0, 0.05);
  // a wider clearance, a smaller circle
  const LimitLines tight = limit_lines(track, flat_envelope(12.0, 5.0, 10.0), 2.0);
  EXPECT_NEAR(tight.min_curvature.lap_time, 2.0 * kPi * std::sqrt(14.0 / 12.0), 0.005 * 6.77);
}

TEST(LimitLines, NotACircuitIsAnError) {
  const std::string acc = read_file(kRoot + "/tracks/acceleration.csv");
  const world::TrackModel track = world::build_track(world::parse_track(acc, "acceleration.csv"));
  try {
    limit_lines(track, flat_envelope(12.0, 5.0, 10.0));
    FAIL() << "no error";
  } catch (const UserError& e) {
    EXPECT_THAT(e.what(), HasSubstr("only a circuit"));
  }
}

TEST(LimitReport, FsgLinesRespectTheEnvelopeAndTheClearance) {
  const Scenario s = load_scenario(kRoot + "/scenarios/fsg_2023_trackdrive.ini");
  const world::TrackModel track = world::build_track(load_track_file(s.track_path));
  const LimitReport r = limit_report(s.vehicle, track, "fsg_2023_trackdrive.ini");
  const LimitLine& racing = r.lines.min_curvature;
  // the racing line bends less and laps faster than the centreline
  EXPECT_LT(r.lines.cost_min_curvature, 0.7 * r.lines.cost_centreline);
  EXPECT_LT(racing.lap_time, 0.95 * r.lines.centreline.lap_time);
  // it keeps the clearance (the optimised points and the half-way points do; the spline within 3 cm)
  EXPECT_GE(racing.clearance_min, r.lines.clearance - 0.03);
  // the car can steer it
  EXPECT_LT(racing.curvature_max, r.steering_curvature);
  // every sample within the envelope: the lateral limit, and the speed
  // change over each step within what the envelope allows at its start
  const auto& pts = racing.trajectory.points;
  const std::size_t n = pts.size();
  const double ds = racing.trajectory.length / static_cast<double>(n);
  for (std::size_t i = 0; i < n; ++i) {
    const TrajectoryPoint &a = pts[i], &b = pts[(i + 1) % n];
    EXPECT_LE(a.speed * a.speed * std::abs(a.curvature), planning::planned_lateral_limit(a.speed, r.envelope) * (1 + 1e-9));
    const double accel = (b.speed * b.speed - a.speed * a.speed) / (2.0 * ds);
    if (accel > 0) EXPECT_LE(accel, planning::available_acceleration(a.speed, a.curvature, r.envelope) + 1e-6) << i;
    else EXPECT_LE(-accel, planning::available_deceleration(b.speed, b.curvature, r.envelope) * 1.05 + 1e-6) << i;
    EXPECT_LE(a.speed, r.ggv.top_speed + 1e-9);
  }
  // the envelope grows with speed (downforce) and loses acceleration to drag
  EXPECT_GT(r.envelope.ggv_lateral.back(), r.envelope.ggv_lateral.front());
  EXPECT_EQ(r.envelope.ggv_accel.back(), 0.0);
}

// a sweep's points share their car's envelope, measured once per process:
// callers on three threads at once get what a measurement of their own
// gives, and another car gets its own
TEST(SharedCarEnvelope, IsTheCarsOwnMeasurementForEveryCaller) {
  const Scenario s = load_scenario(kRoot + "/scenarios/fsg_2023_trackdrive.ini");
  std::vector<std::string> got(3);
  std::vector<std::thread> threads;
  for (std::size_t i = 0; i < got.size(); ++i) {
    threads.emplace_back([&, i] { got[i] = params::fingerprint(shared_car_envelope(s.vehicle)); });
  }
  for (std::thread& t : threads) t.join();
  const std::string own = params::fingerprint(car_envelope(s.vehicle));
  for (const std::string& g : got) EXPECT_EQ(g, own);
  vehicle::VehicleParams heavier = s.vehicle;
  heavier.mass *= 1.25;
  const std::string heavy = params::fingerprint(shared_car_envelope(heavier));
  EXPECT_NE(heavy, own);
  EXPECT_EQ(params::fingerprint(shared_car_envelope(heavier)), heavy);
  EXPECT_EQ(params::fingerprint(shared_car_envelope(s.vehicle)), own);
}

// PADDOCK_CACHE_DIR for one test, restored after it
class CacheDirFor {
 public:
  explicit CacheDirFor(const std::string& dir) {
    if (const char* old = std::getenv("PADDOCK_CACHE_DIR")) old_ = old;
    setenv("PADDOCK_CACHE_DIR", dir.c_str(), 1);
  }
  ~CacheDirFor() {
    if (old_) setenv("PADDOCK_CACHE_DIR", old_->c_str(), 1);
    else unsetenv("PADDOCK_CACHE_DIR");
  }

 private:
  std::optional<std::string> old_;
};

std::vector<fs::path> files_in(const std::string& dir) {
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(dir)) out.push_back(e.path());
  return out;
}

// the car's envelope kept between runs: what a run reads back is what a
// measurement gives, bit for bit; it is read (not measured again) while
// the file is whole, and measured again and rewritten when the file is of
// another build or broken; the folder keeps the latest 64 entries
TEST(KeptCarEnvelope, ReadsBackTheMeasurementAndMeasuresAgainWhenTheFileIsNotWhole) {
  const std::string dir = scratch("cache");
  fs::remove_all(dir);
  const CacheDirFor env(dir);
  const Scenario s = load_scenario(kRoot + "/scenarios/fsg_2023_trackdrive.ini");
  const std::string own = params::fingerprint(car_envelope(s.vehicle));

  // 70 entries of other builds, older than what the run writes: the 64
  // latest entries are kept, the new one among them
  fs::create_directories(dir);
  for (int i = 0; i < 70; ++i) {
    const std::string old = dir + "/car-envelope-old" + std::to_string(i) + ".ini";
    write_file_atomic(old, "[cache]\nbuild = another\n");
    fs::last_write_time(old, fs::file_time_type::clock::now() - std::chrono::hours(1000 - i));
  }
  write_file_atomic(dir + "/notes.txt", "not an entry: left alone\n");
  EXPECT_EQ(params::fingerprint(kept_car_envelope(s.vehicle)), own);  // measured and kept
  EXPECT_EQ(files_in(dir).size(), 65u);
  EXPECT_FALSE(fs::exists(dir + "/car-envelope-old6.ini"));  // the oldest seven are gone
  EXPECT_TRUE(fs::exists(dir + "/car-envelope-old7.ini"));
  for (int i = 0; i < 70; ++i) fs::remove(dir + "/car-envelope-old" + std::to_string(i) + ".ini");
  fs::remove(dir + "/notes.txt");
  const std::vector<fs::path> kept = files_in(dir);
  ASSERT_EQ(kept.size(), 1u);
  const std::string text = read_file(kept[0].string());
  EXPECT_THAT(text, HasSubstr("build = " + program_build_id() + "\n"));

  // read back: a value changed in the file (within its bounds) is what a run gets
  const auto with = [&](const std::string& from, const std::string& to) {
    std::string t = text;
    const auto at = t.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) t.replace(at, from.size(), to);
    return t;
  };
  write_file_atomic(kept[0].string(), with("\nax_max = 8\n", "\nax_max = 7.5\n"));
  EXPECT_EQ(kept_car_envelope(s.vehicle).ax_max, 7.5);

  // another build's entry, a truncated file, a value out of its bounds:
  // measured again, and the file rewritten as it was
  for (const std::string& broken : {with("build = ", "build = 0"), text.substr(0, text.size() / 2),
                                    with("\nax_max = 8\n", "\nax_max = -1\n")}) {
    write_file_atomic(kept[0].string(), broken);
    EXPECT_EQ(params::fingerprint(kept_car_envelope(s.vehicle)), own);
    EXPECT_EQ(read_file(kept[0].string()), text);
  }
  EXPECT_EQ(files_in(dir).size(), 1u);  // no temporary file left
}

TEST(CacheDir, FromTheEnvironmentAndOffWhenSetEmpty) {
  {
    const CacheDirFor env("/some/where");
    EXPECT_EQ(cache_dir(), "/some/where");
  }
  const CacheDirFor off("");
  EXPECT_EQ(cache_dir(), "");
}

// the build ID is the one the linker wrote (readelf's reading of this program)
TEST(ProgramBuildId, IsTheLinkersNote) {
  const std::string id = program_build_id();
  ASSERT_EQ(id.size(), 40u) << id;  // the linker's default: SHA-1
  const std::string out = scratch("readelf.txt");
  ASSERT_EQ(std::system(("readelf -n /proc/" + std::to_string(::getpid()) + "/exe > " + out).c_str()), 0);
  EXPECT_THAT(read_file(out), HasSubstr("Build ID: " + id + "\n"));
}

TEST(GgvEnvelope, NodesFromTheRowsAndTheGripLineUnderTheLock) {
  // grip rows on ay = 16 + 0.005 v^2; a row bounded by the steering lock
  // takes the line's value; nodes at rest and at the top speed
  std::vector<GgvRow> rows;
  for (double v : {5.0, 10.0, 15.0, 20.0}) {
    GgvRow g;
    g.speed = v;
    g.lateral = v == 5.0 ? 9.0 : 16.0 + 0.005 * v * v;
    g.lateral_limit = v == 5.0 ? "steering lock" : "grip";
    g.acceleration = 14.0 - 0.2 * v;
    g.braking = 15.0;
    rows.push_back(g);
  }
  const planning::VelocityProfileParams e = ggv_envelope(rows, 27.0);
  ASSERT_EQ(e.ggv_speed, (std::vector<double>{0.0, 5.0, 10.0, 15.0, 20.0, 27.0}));
  EXPECT_NEAR(e.ggv_lateral[0], 16.0, 1e-9);
  EXPECT_NEAR(e.ggv_lateral[1], 16.125, 1e-9);
  EXPECT_NEAR(e.ggv_lateral[3], 16.0 + 0.005 * 225.0, 1e-9);
  EXPECT_EQ(e.ggv_accel.front(), 13.0);
  EXPECT_EQ(e.ggv_accel.back(), 0.0);
  EXPECT_EQ(e.limits, planning::VelocityProfileParams::Ggv);
  EXPECT_EQ(params::validate(e), "");
  // the stack's lines read back to the same envelope
  EXPECT_THAT(ggv_ini(e), HasSubstr("ggv_speed = 0.00, 5.00, 10.00, 15.00, 20.00, 27.00\n"));
}

using paddock::testing::Outcome;
Outcome paddock(const std::string& args) { return paddock::testing::run_paddock(args); }

TEST(ReportLimitCli, WritesItsFilesAndRejectsBadInput) {
  const std::string out = scratch("fsg");
  fs::remove_all(out);
  Outcome o = paddock("report limit " + kRoot + "/scenarios/fsg_2023_trackdrive.ini --out " + out + " --map-size 400");
  ASSERT_EQ(o.code, 0) << o.output;
  EXPECT_THAT(o.output, HasSubstr("min_curvature"));
  const auto j = nlohmann::json::parse(read_file(out + "/limit_report.json"));
  EXPECT_GT(j["centreline"]["lap_time"].get<double>(), j["limit_lap_s"].get<double>());
  EXPECT_TRUE(fs::exists(out + "/limit.png"));
  EXPECT_THAT(read_file(out + "/limit_lines.csv"), HasSubstr("line,s,x,y,heading,curvature,speed\n"));

  o = paddock("report limit " + kRoot + "/scenarios/skidpad.ini --out " + scratch("skid"));
  EXPECT_EQ(o.code, 2);
  EXPECT_THAT(o.output, HasSubstr("only a circuit"));
  o = paddock("report limit " + kRoot + "/scenarios/fsg_2023_trackdrive.ini --clearance -1");
  EXPECT_EQ(o.code, 2);
  EXPECT_THAT(o.output, HasSubstr("--clearance: expected a distance >= 0 m"));
  o = paddock("report limit");
  EXPECT_EQ(o.code, 2);
  EXPECT_THAT(o.output, HasSubstr("report limit needs a scenario file"));
}

}  // namespace
}  // namespace paddock::runner
