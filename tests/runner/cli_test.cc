// the paddock program as a user runs it: exit codes, file:line messages,
// output files, and determinism of a whole run
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>

#include "sim/runner/files.h"
#include "tests/runner/run_paddock.h"

namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

const std::string kRoot = PADDOCK_SOURCE_DIR;

using paddock::testing::Outcome;
Outcome paddock(const std::string& args) { return paddock::testing::run_paddock(args); }

std::string scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / "paddock_cli_test";
  fs::create_directories(d);
  return (d / name).string();
}

// a scenario in scenarios/ (so that its include resolves), removed afterwards
struct TempScenario {
  std::string path;
  explicit TempScenario(const std::string& name, const std::string& text) : path(kRoot + "/scenarios/_cli_" + name + ".ini") {
    std::ofstream(path) << text;
  }
  ~TempScenario() { fs::remove(path); }
};

TEST(Cli, MalformedIniIsAFileLineErrorAndExit2) {
  TempScenario s("malformed", "include = vehicles/default.ini\n[scenario\ntrack = x\n");
  const auto o = paddock("run " + s.path + " --out " + scratch("malformed"));
  EXPECT_EQ(o.code, 2);
  EXPECT_THAT(o.output, HasSubstr(s.path + ":2: malformed section header"));
}

TEST(Cli, UnknownKeyIsAFileLineErrorAndExit2) {
  TempScenario s("unknown", "include = vehicles/default.ini\n[scenario]\ntrack = ../tracks/fsg_2023.csv\nlaps = 3\n");
  const auto o = paddock("run " + s.path + " --out " + scratch("unknown"));
  EXPECT_EQ(o.code, 2);
  EXPECT_THAT(o.output, HasSubstr(s.path + ":4: unknown key 'laps' in [scenario]"));
}

TEST(Cli, BadOverrideIsAnErrorAndExit2) {
  const auto o = paddock("run " + kRoot + "/scenarios/fsg_2023_trackdrive.ini --set control.lateral=lqr --out " + scratch("ov"));
  EXPECT_EQ(o.code, 2);
  EXPECT_THAT(o.output, HasSubstr("--set:1: [control] lateral = 'lqr' is not known"));
}

TEST(Cli, ThreadsMustBeAWholeNumberInRange) {
  for (const char* bad : {"0", "65", "two", "2.5", ""}) {
    const auto o = paddock("run " + kRoot + "/scenarios/acceleration.ini --threads '" + bad + "' --out " + scratch("threads"));
    EXPECT_EQ(o.code, 2) << bad;
    EXPECT_THAT(o.output, HasSubstr("--threads " + std::string(bad) + ": expected a whole number from 1 to 64"));
  }
  const auto o = paddock("run " + kRoot + "/scenarios/acceleration.ini --threads");
  EXPECT_EQ(o.code, 2);
  EXPECT_THAT(o.output, HasSubstr("--threads needs a value"));
  // the replay's likewise (checked before the log is read)
  for (const char* bad : {"0", "65", "two"}) {
    const auto r = paddock("replay " + scratch("no_such.mcap") + " --threads '" + bad + "'");
    EXPECT_EQ(r.code, 2) << bad;
    EXPECT_THAT(r.output, HasSubstr("--threads " + std::string(bad) + ": expected a whole number from 1 to 64"));
  }
}

TEST(Cli, MissingScenarioFileIsNamed) {
  const auto o = paddock("run " + kRoot + "/scenarios/no_such.ini");
  EXPECT_EQ(o.code, 2);
  EXPECT_THAT(o.output, HasSubstr("no_such.ini: cannot open"));
}

TEST(Cli, MissingTrackFileIsNamed) {
  TempScenario s("notrack", "include = vehicles/default.ini\n[scenario]\ntrack = ../tracks/nowhere.csv\n");
  const auto o = paddock("run " + s.path + " --out " + scratch("notrack"));
  EXPECT_EQ(o.code, 2);
  EXPECT_THAT(o.output, HasSubstr("nowhere.csv: cannot open"));
}

TEST(Cli, BadTrackFileIsAFileLineError) {
  const std::string bad = scratch("bad_track.csv");
  paddock::runner::write_file_atomic(bad, "tag,x,y\nblue,1,2\npurple,3,4\n");
  TempScenario s("badtrack", "include = vehicles/default.ini\n[scenario]\ntrack = " + bad + "\n");
  const auto o = paddock("run " + s.path + " --out " + scratch("badtrack"));
  EXPECT_EQ(o.code, 2);
  EXPECT_THAT(o.output, HasSubstr(bad + ":3:"));
  const auto c = paddock("check-track " + bad);
  EXPECT_EQ(c.code, 2);
  EXPECT_THAT(c.output, HasSubstr(bad + ":3:"));
}

TEST(Cli, CheckTrackDescribesEveryShippedTrack) {
  std::string files;
  int n = 0;
  for (const auto& e : fs::directory_iterator(kRoot + "/tracks")) {
    if (e.path().extension() == ".csv") {
      files += " " + e.path().string();
      ++n;
    }
  }
  const auto o = paddock("check-track" + files);
  EXPECT_EQ(o.code, 0) << o.output;
  EXPECT_EQ(n, 18);
}

std::string without_wall_clock(std::string json) {
  // the fields that measure the machine, not the run
  json = std::regex_replace(json, std::regex("\"wall_time\":[^,]*,"), "");
  json = std::regex_replace(json, std::regex("\"update_ms_mean\":[^,]*,"), "");
  json = std::regex_replace(json, std::regex("\"update_ms_p99\":[^,]*,"), "");
  json = std::regex_replace(json, std::regex("\"profile\":\\{[^}]*\\},"), "");
  json = std::regex_replace(json, std::regex("\"page_faults\":[^,]*,"), "");
  json = std::regex_replace(json, std::regex("\"allocations\":(null|\\{[^}]*\\}),"), "");
  json = std::regex_replace(json, std::regex("\"peak_rss_mb\":[^,]*,"), "");
  return std::regex_replace(json, std::regex("\"realtime_factor\":[^,]*,"), "");
}

// FNV-1a, 64 bit: the log's fingerprint (not a cryptographic hash; it need
// only change when a byte changes)
std::uint64_t fnv1a64(const std::string& bytes) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (const unsigned char c : bytes) {
    h ^= c;
    h *= 0x100000001b3ULL;
  }
  return h;
}

// the pinned fingerprint for this CPU's maker: tests/data/determinism.txt,
// line "log_fnv1a64_intel = 0x..." on Intel, else "log_fnv1a64 = 0x...";
// "unmeasured" when it has not been measured on that maker since the last
// change of a result (why a maker has its own: the file's header)
std::string pinned_log_hash() {
  const std::string text = paddock::runner::read_file(kRoot + "/tests/data/determinism.txt");
  __builtin_cpu_init();
  const std::string key = __builtin_cpu_is("intel") ? "log_fnv1a64_intel" : "log_fnv1a64";
  std::smatch m;
  if (!std::regex_search(text, m, std::regex("(^|\n)" + key + " = (0x[0-9a-f]{16}|unmeasured)(\n|$)"))) return "";
  return m[2];
}

TEST(Cli, SameScenarioAndSeedGiveIdenticalSummaryAndLog) {
  // the default scenario (raw LiDAR and camera, perception, planning,
  // control), its first 40 s after the go: the lap of exploration and more
  const std::string scenario = kRoot + "/scenarios/fsg_2023_trackdrive.ini --set event.timeout=40";
  const auto a = paddock("run " + scenario + " --out " + scratch("det_a"));
  // the second on three threads (the camera beside the LiDAR, the particles
  // split three ways): the result must not change
  const auto b = paddock("run " + scenario + " --threads 3 --out " + scratch("det_b"));
  ASSERT_EQ(a.code, 0) << a.output;
  ASSERT_EQ(b.code, 0) << b.output;
  const std::string log_a = paddock::runner::read_file(scratch("det_a") + "/log.csv");
  const std::string log_b = paddock::runner::read_file(scratch("det_b") + "/log.csv");
  EXPECT_GT(log_a.size(), 100000u);
  EXPECT_TRUE(log_a == log_b) << "log.csv differs between two runs (one on 1 thread, one on 3)";
  // and the same as the build that pinned it: a change of any result shows here
  char hash[19];
  std::snprintf(hash, sizeof hash, "0x%016llx", static_cast<unsigned long long>(fnv1a64(log_a)));
  // (pinned for machines with AVX2 and FMA, Embree's kernels and glibc's
  // libm the same there; other machines round differently)
  const std::string pinned = pinned_log_hash();
  if (pinned == "unmeasured") {
    std::printf("the log's hash %s: not pinned for this CPU's maker yet (tests/data/determinism.txt)\n", hash);
  } else if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) {
    EXPECT_EQ(std::string(hash), pinned)
        << "the default run's log changed; if on purpose, set "
        << (__builtin_cpu_is("intel") ? "log_fnv1a64_intel" : "log_fnv1a64") << " = " << hash
        << " in tests/data/determinism.txt (the other maker's too, measured there) and say why in the commit";
  } else {
    std::printf("no AVX2 and FMA here: the log's hash %s is not compared with the pinned one\n", hash);
  }
  const std::string sum_a = paddock::runner::read_file(scratch("det_a") + "/summary.json");
  const std::string sum_b = paddock::runner::read_file(scratch("det_b") + "/summary.json");
  EXPECT_EQ(without_wall_clock(sum_a), without_wall_clock(sum_b));
  EXPECT_THAT(sum_a, HasSubstr("\"mode\":\"lidar_camera\""));
  EXPECT_THAT(sum_a, HasSubstr("\"laps\":[{\"lap\":1"));
  // the resolved scenario is written next to the results and runs again the
  // same: its first 10 s after the go are the first rows of the log
  const auto c = paddock("run " + scratch("det_a") + "/scenario.ini --set event.timeout=10 --out " + scratch("det_c"));
  ASSERT_EQ(c.code, 0) << c.output;
  const std::string log_c = paddock::runner::read_file(scratch("det_c") + "/log.csv");
  EXPECT_GT(log_c.size(), 30000u);
  EXPECT_LT(log_c.size(), log_a.size());
  EXPECT_TRUE(log_a.compare(0, log_c.size(), log_c) == 0) << "the resolved scenario's run differs";
}

TEST(Cli, WithAPerceptionLatencyTheScansGoOnAThreadOfTheirOwnAndTheResultStays) {
  // the default scenario's first 20 s after the go with a rotation's latency:
  // on one thread, and on two (the scans processed beside the loop, and
  // each frame's SLAM update after them on the scans' thread): the same log
  const std::string scenario =
      kRoot + "/scenarios/fsg_2023_trackdrive.ini --set event.timeout=20 --set perception.latency=0.1";
  const auto a = paddock("run " + scenario + " --out " + scratch("lat_a"));
  const auto b = paddock("run " + scenario + " --threads 2 --out " + scratch("lat_b"));
  ASSERT_EQ(a.code, 0) << a.output;
  ASSERT_EQ(b.code, 0) << b.output;
  const std::string log_a = paddock::runner::read_file(scratch("lat_a") + "/log.csv");
  EXPECT_GT(log_a.size(), 50000u);
  EXPECT_TRUE(log_a == paddock::runner::read_file(scratch("lat_b") + "/log.csv"))
      << "log.csv differs between one thread and two";
  const std::string resolved = paddock::runner::read_file(scratch("lat_b") + "/scenario.ini");
  // a key of a section of a resolved scenario
  const auto key = [](const std::string& text, const std::string& section, const std::string& k) {
    std::smatch m;
    // the section's own lines (up to the next header) down to the key
    const std::regex re("\\[" + section + R"(\]\n(?:[^\[\n][^\n]*\n)*?)" + k + R"( = ([^ ;\n]+))");
    return std::regex_search(text, m, re) ? m[1].str() : std::string("?");
  };
  EXPECT_EQ(key(resolved, "perception", "threads"), "2");
  EXPECT_EQ(key(resolved, "slam", "threads"), "1");
  EXPECT_EQ(key(resolved, "sim", "threads"), "2");
  // without the latency nothing could go on beside the loop: the particles take the second thread
  const auto c = paddock("run " + kRoot + "/scenarios/acceleration.ini --threads 2 --out " + scratch("lat_c"));
  ASSERT_EQ(c.code, 0) << c.output;
  const std::string resolved_c = paddock::runner::read_file(scratch("lat_c") + "/scenario.ini");
  EXPECT_EQ(key(resolved_c, "perception", "latency"), "0");
  EXPECT_EQ(key(resolved_c, "perception", "threads"), "1");
  EXPECT_EQ(key(resolved_c, "slam", "threads"), "2");
}

TEST(Cli, JsonSummaryCarriesTheSchema) {
  const auto o = paddock("run " + kRoot + "/scenarios/fsg_2019_autocross.ini --json --out " + scratch("json"));
  ASSERT_EQ(o.code, 0) << o.output;
  for (const char* key : {"\"scenario\":", "\"event\":\"autocross\"", "\"finished\":", "\"laps\":[", "\"penalties\":{",
                          "\"doo\":", "\"oc\":", "\"uss\":", "\"raw_time\":", "\"total_time\":", "\"sim_time\":",
                          "\"wall_time\":", "\"realtime_factor\":", "\"tracking\":{", "\"rms\":", "\"max\":", "\"itae\":",
                          "\"slide_samples\":"}) {
    EXPECT_THAT(o.output, HasSubstr(key));
  }
  EXPECT_EQ(o.output.front(), '{');
  // the car's limit lap on this circuit, and every lap above it (no lap can
  // beat the car's own quasi-steady-state limit; a standing lap least of all)
  const auto j = nlohmann::json::parse(o.output);
  ASSERT_TRUE(j["limit_lap_s"].is_number()) << j["limit_lap_s"];
  const double limit = j["limit_lap_s"].get<double>();
  EXPECT_GT(limit, 5.0);
  ASSERT_FALSE(j["laps"].empty());
  for (const auto& lap : j["laps"]) {
    EXPECT_NEAR(lap["above_limit"].get<double>(), lap["time"].get<double>() / limit - 1.0, 1e-12);
    EXPECT_GT(lap["above_limit"].get<double>(), 0.0);
  }
  // a track without a lap has no limit
  const auto acc = paddock("run " + kRoot + "/scenarios/acceleration.ini --json --out " + scratch("json_acc"));
  ASSERT_EQ(acc.code, 0) << acc.output;
  EXPECT_TRUE(nlohmann::json::parse(acc.output)["limit_lap_s"].is_null());
}

// --profile: the stages' table; summary.json's "profile" has every stage,
// none negative, their sum within the run's wall time (the stages and
// "other" partition the closed loop's time, which the wall time includes)
TEST(Cli, ProfileSaysWhereTheWallTimeWent) {
  const auto o = paddock("run " + kRoot + "/scenarios/acceleration.ini --profile --out " +
                         scratch("profile"));
  ASSERT_EQ(o.code, 0) << o.output;
  EXPECT_THAT(o.output, HasSubstr("where the wall time went (--profile):\n| stage | wall s | share | ms per simulated s |"));
  const auto j = nlohmann::json::parse(paddock::runner::read_file(scratch("profile") + "/summary.json"));
  double sum = 0.0;
  for (const char* stage : {"other", "physics", "lidar", "camera", "perception", "localisation", "planning", "control",
                            "logging", "scoring"}) {
    ASSERT_TRUE(j["profile"][stage].is_number()) << stage;
    const double s = j["profile"][stage].get<double>();
    EXPECT_GE(s, 0.0) << stage;
    sum += s;
    EXPECT_THAT(o.output, HasSubstr(std::string("\n| ") + stage + " | ")) << stage;
  }
  EXPECT_EQ(j["profile"].size(), 10u);
  EXPECT_LE(sum, j["wall_time"].get<double>());
  // a run on raw sensors casts rays and perceives
  EXPECT_GT(j["profile"]["lidar"].get<double>(), 0.0);
  EXPECT_GT(j["profile"]["perception"].get<double>(), 0.0);
  EXPECT_GT(j["profile"]["physics"].get<double>(), 0.0);
  // the process holds at least the track and the stack; the loop touches new pages
  EXPECT_GT(j["peak_rss_mb"].get<double>(), 10.0);
  EXPECT_GE(j["page_faults"].get<long>(), 0);
  EXPECT_THAT(o.output, HasSubstr(" MiB\n"));
  // the allocations, by stage, add up to their total; the stack's map and
  // messages allocate, so a run of any length makes some (a sanitizer's
  // build does not count them: null)
#if defined(__SANITIZE_ADDRESS__)
  EXPECT_TRUE(j["allocations"].is_null());
#else
  ASSERT_TRUE(j["allocations"].is_object()) << j["allocations"];
  std::uint64_t stages = 0;
  for (const auto& [name, n] : j["allocations"].items())
    if (name != "total") stages += n.get<std::uint64_t>();
  EXPECT_EQ(j["allocations"].size(), 11u);
  EXPECT_EQ(stages, j["allocations"]["total"].get<std::uint64_t>());
  EXPECT_GT(j["allocations"]["localisation"].get<std::uint64_t>(), 0u);
  EXPECT_THAT(o.output, HasSubstr(" allocations per simulated s |"));
#endif
}

TEST(Cli, FailedExpectationsExitWith3AndSayWhich) {
  TempScenario s("expect", "include = fsg_2019_autocross.ini\n[expect]\nlap_time_max = 5\n");
  const auto o = paddock("run " + s.path + " --out " + scratch("expect"));
  EXPECT_EQ(o.code, 3);
  EXPECT_THAT(o.output, HasSubstr("lap 1 time: expected at most 5.000 s"));
}

}  // namespace
