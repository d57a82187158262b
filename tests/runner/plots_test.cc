// the figures of a run as a user gets them: `run --plots` and `plot DIR`, their
// sizes, and clear errors for missing, broken or unwritable files
#include "sim/runner/plots.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "render/figures.h"
#include "sim/runner/files.h"
#include "tests/runner/run_paddock.h"

namespace paddock::runner {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

const std::string kRoot = PADDOCK_SOURCE_DIR;

using paddock::testing::Outcome;
Outcome paddock(const std::string& args) { return paddock::testing::run_paddock(args); }

std::string scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / "paddock_plots_test" / name;
  fs::remove_all(d);
  fs::create_directories(d.parent_path());
  return d.string();
}

render::Image png_at(const std::string& path) {
  const std::string bytes = read_file(path);
  return render::decode_png(std::vector<std::uint8_t>(bytes.begin(), bytes.end()));
}

TEST(Plots, RunWithPlotsDrawsTheThreeFiguresAtTheDefaultSizes) {
  const std::string dir = scratch("run");
  const auto o = paddock("run " + kRoot + "/scenarios/fsg_2019_autocross.ini --plots --out " + dir);
  ASSERT_EQ(o.code, 0) << o.output;
  EXPECT_THAT(o.output, HasSubstr(dir + "/map.png"));
  const render::Image map = png_at(dir + "/map.png");
  EXPECT_EQ(map.width, 1600);
  EXPECT_EQ(map.height, 1600);
  const render::Image ctl = png_at(dir + "/controller.png");
  EXPECT_EQ(ctl.width, 1600);
  EXPECT_EQ(ctl.height, 1200);
  const render::Image laps = png_at(dir + "/laps.png");
  EXPECT_EQ(laps.width, 1600);
  EXPECT_EQ(laps.height, 1200);
  // a circuit: the run wrote the car's limit lines, and the best lap is drawn over them
  EXPECT_THAT(read_file(dir + "/limit_lines.csv"), HasSubstr("\nmin_curvature,"));
  EXPECT_EQ(png_at(dir + "/limit.png").width, 1600);
  // a figure is a picture, not a blank page: many pixels differ from the corner
  int drawn = 0;
  const render::Rgba bg = map.pixel(0, 0);
  for (int y = 0; y < map.height; y += 4)
    for (int x = 0; x < map.width; x += 4) drawn += map.pixel(x, y) == bg ? 0 : 1;
  EXPECT_GT(drawn, 2000);
}

TEST(Plots, RawSensorRunsWriteThePerceptionSnapshotAndItsFigures) {
  // lidar_camera: the snapshot (perception.json, camera.png) and both
  // perception figures; the snapshot's camera image is the camera's size and
  // its detections lie near true cones
  const std::string dir = scratch("perception");
  const auto o = paddock("run " + kRoot + "/scenarios/fsg_2023_trackdrive.ini --set event.timeout=10 --set sim.snapshot_time=8 --plots --out " + dir);
  ASSERT_EQ(o.code, 0) << o.output;
  EXPECT_THAT(o.output, HasSubstr(dir + "/lidar_view.png"));
  EXPECT_THAT(o.output, HasSubstr(dir + "/camera_view.png"));
  const render::Image cam = png_at(dir + "/camera.png");
  EXPECT_EQ(cam.width, 800);
  EXPECT_EQ(cam.height, 500);
  EXPECT_EQ(png_at(dir + "/lidar_view.png").width, 1600);
  const auto j = nlohmann::json::parse(read_file(dir + "/perception.json"));
  EXPECT_NEAR(j.at("t").get<double>(), 8.0, 0.11);
  ASSERT_GT(j.at("points").size(), 5000u);
  ASSERT_GT(j.at("detected").size(), 5u);
  for (const auto& d : j.at("detected")) {
    double best = 1e9;
    for (const auto& t : j.at("truth"))
      best = std::min(best, std::hypot(d.at(0).get<double>() - t.at(0).get<double>(), d.at(1).get<double>() - t.at(1).get<double>()));
    EXPECT_LT(best, 0.3);
  }
  EXPECT_GT(j.at("camera").at("boxes").size(), 3u);
  // the snapshot names its image: a name in the run's folder, never a path out of it
  nlohmann::json bad = j;
  bad["camera"]["image"] = "../perception_lidar/camera.png";
  {
    std::ofstream f(dir + "/perception.json");
    f << bad.dump();
  }
  const auto escaped = paddock("plot " + dir);
  EXPECT_EQ(escaped.code, 2) << escaped.output;
  EXPECT_THAT(escaped.output, HasSubstr("camera.image '../perception_lidar/camera.png': expected a file name in"));
  // lidar alone: no camera, so no camera figure
  const std::string lidar_dir = scratch("perception_lidar");
  const auto l = paddock("run " + kRoot + "/scenarios/fsg_2023_trackdrive.ini --set autonomy.perception=lidar --set event.timeout=10 --set sim.snapshot_time=8 --plots --out " + lidar_dir);
  ASSERT_EQ(l.code, 0) << l.output;
  EXPECT_TRUE(fs::exists(lidar_dir + "/lidar_view.png"));
  EXPECT_FALSE(fs::exists(lidar_dir + "/camera_view.png"));
  EXPECT_FALSE(fs::exists(lidar_dir + "/camera.png"));
}

TEST(Plots, SlamRunsWriteTheirSeriesAndTheSlamFigures) {
  // slam != ground_truth: slam.csv holds the estimate against the truth at
  // every sample, its errors are the summary's ATE, and two figures draw it
  const std::string dir = scratch("slam");
  const auto o = paddock("run " + kRoot + "/scenarios/fsg_2023_trackdrive.ini --set autonomy.slam=fastslam "
                         "--set autonomy.perception=ground_truth --set event.timeout=12 --plots --out " + dir);
  ASSERT_EQ(o.code, 0) << o.output;
  EXPECT_THAT(o.output, HasSubstr(dir + "/slam_map.png"));
  EXPECT_EQ(png_at(dir + "/slam_map.png").width, 1600);
  EXPECT_EQ(png_at(dir + "/slam_error.png").height, 1200);
  const std::vector<SlamSample> series = parse_slam_csv(read_file(dir + "/slam.csv"), dir + "/slam.csv");
  const auto j = nlohmann::json::parse(read_file(dir + "/summary.json")).at("slam");
  ASSERT_EQ(static_cast<long>(series.size()), j.at("samples").get<long>());
  double sum2 = 0.0, worst = 0.0;
  for (const SlamSample& x : series) {
    EXPECT_NEAR(x.error, std::hypot(x.estimate.x - x.truth.x, x.estimate.y - x.truth.y), 1e-9);
    sum2 += x.error * x.error;
    worst = std::max(worst, x.error);
  }
  EXPECT_NEAR(std::sqrt(sum2 / static_cast<double>(series.size())), j.at("ate_rms_m").get<double>(), 1e-9);
  EXPECT_EQ(worst, j.at("ate_max_m").get<double>());
  // the same folder run again with the true state: no SLAM series left behind
  ASSERT_EQ(paddock("run " + kRoot + "/scenarios/fsg_2023_trackdrive.ini --set autonomy.perception=ground_truth "
                    "--set autonomy.slam=ground_truth --set event.timeout=2 --out " + dir).code, 0);
  EXPECT_FALSE(fs::exists(dir + "/slam.csv"));
}

TEST(Plots, PlotRedrawsAFinishedRunWithOtherSizesAndTheSameFiles) {
  const std::string dir = scratch("redraw");
  ASSERT_EQ(paddock("run " + kRoot + "/scenarios/skidpad.ini --plots --out " + dir).code, 0);
  const std::string first = read_file(dir + "/map.png");
  // the same options draw the same bytes
  ASSERT_EQ(paddock("plot " + dir).code, 0);
  EXPECT_TRUE(read_file(dir + "/map.png") == first);
  const auto o = paddock("plot " + dir + " --map-size 800 --chart-size 900x600 --dpi 100");
  ASSERT_EQ(o.code, 0) << o.output;
  EXPECT_EQ(png_at(dir + "/map.png").width, 800);
  EXPECT_EQ(png_at(dir + "/controller.png").width, 900);
  EXPECT_EQ(png_at(dir + "/controller.png").height, 600);
}

TEST(Plots, MissingRunFolderIsNamed) {
  const auto o = paddock("plot " + scratch("nothing_here"));
  EXPECT_EQ(o.code, 2);
  EXPECT_THAT(o.output, HasSubstr("nothing_here/scenario.ini: cannot open"));
}

TEST(Plots, BrokenLogIsAFileLineError) {
  const std::string dir = scratch("broken");
  ASSERT_EQ(paddock("run " + kRoot + "/scenarios/acceleration.ini --out " + dir).code, 0);
  std::string log = read_file(dir + "/log.csv");
  // break the fourth line (the third row)
  std::size_t pos = 0;
  for (int i = 0; i < 3; ++i) pos = log.find('\n', pos) + 1;
  log.insert(pos, "oops,");
  write_file_atomic(dir + "/log.csv", log);
  const auto o = paddock("plot " + dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_THAT(o.output, HasSubstr(dir + "/log.csv:4: column 1 is not a number"));
}

TEST(Plots, UnwritableOutputIsAClearError) {
  const std::string dir = scratch("unwritable");
  ASSERT_EQ(paddock("run " + kRoot + "/scenarios/acceleration.ini --out " + dir).code, 0);
  fs::create_directories(dir + "/map.png/in_the_way");  // a folder where the figure goes
  const auto o = paddock("plot " + dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_THAT(o.output, HasSubstr(dir + "/map.png: cannot rename into place"));
  // and a run whose output folder cannot be made
  const std::string a_file = scratch("a_file");
  write_file_atomic(a_file, "x");
  const auto r = paddock("run " + kRoot + "/scenarios/acceleration.ini --out " + a_file + "/sub");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.output, HasSubstr("cannot create folder"));
}

TEST(Plots, BadPlotOptionsAreErrors) {
  EXPECT_THAT(paddock("plot x --map-size 10").output, HasSubstr("--map-size 10: expected a whole number from 200 to 10000"));
  EXPECT_THAT(paddock("plot x --chart-size 800").output, HasSubstr("expected WIDTHxHEIGHT"));
}

TEST(LogCsv, ParsesWhatTheRunWritesAndRejectsTheRest) {
  const std::string header =
      "t,x,y,yaw,vx,vy,yaw_rate,steer_cmd,steer,throttle,brake,v_ref,lateral_error,heading_error,s,lap,as_state\n";
  const auto rows = parse_log_csv(header + "0.5,1,2,0.1,3,0,0,0,0,1,0,4,-0.25,0,7,1,2\n", "l.csv");
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].t, 0.5);
  EXPECT_EQ(rows[0].lateral_error, -0.25);
  EXPECT_EQ(rows[0].lap, 1);
  EXPECT_EQ(rows[0].as_state, 2);
  auto error = [](const std::string& text) {
    try {
      parse_log_csv(text, "l.csv");
    } catch (const UserError& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  EXPECT_THAT(error("a,b\n"), HasSubstr("l.csv:1: not a paddock log"));
  EXPECT_THAT(error(header + "1,2,3\n"), HasSubstr("l.csv:2: column 3"));
  EXPECT_THAT(error(""), HasSubstr("l.csv: empty file"));
  // slam.csv the same way
  EXPECT_EQ(parse_slam_csv("t,x,y,yaw,x_true,y_true,yaw_true,error,sigma\n1,2,3,0,2,3.5,0,0.5,0.1\n", "s.csv")[0].error, 0.5);
  try {
    parse_slam_csv("t,x,y,yaw,x_true,y_true,yaw_true,error,sigma\n1,2,x,0,2,3.5,0,0.5,0.1\n", "s.csv");
    ADD_FAILURE() << "no error";
  } catch (const UserError& e) {
    EXPECT_THAT(e.what(), HasSubstr("s.csv:2: column 3"));
  }
}

}  // namespace
}  // namespace paddock::runner
