// a run's log (paddock run ... --log: run.mcap) and its replay (paddock
// replay): the official MCAP reader reads the log whole, with every topic a
// team opens in Foxglove; the replay, with no simulator, hands the stack the
// recorded packets and frames through the car's decoders and gets the live
// run's commands to the bit; a changed stack (--set) is told where it
// differs; a file that is no log, or a cut one, is a clear error; a replay
// writes nothing and reads nothing a hostile log names
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "autonomy/log/mcap.h"
#include "tests/runner/run_paddock.h"

namespace paddock::runner {
namespace {

namespace fs = std::filesystem;
const std::string kRoot = PADDOCK_SOURCE_DIR;

// the wire autocross cut 7 s after the go (at 5 s), logged once per test
// process (ctest runs the tests as processes side by side: each its own)
const fs::path& logged_run() {
  static const fs::path dir = [] {
    const fs::path d = fs::temp_directory_path() / ("paddock_run_log_test_" + std::to_string(::getpid()));
    fs::remove_all(d);
    const testing::Outcome o = testing::run_paddock("run " + kRoot + "/scenarios/fsg_2023_autocross_wire.ini" +
                                                    " --set event.timeout=7 --log --quiet --out " + d.string());
    EXPECT_TRUE(fs::exists(d / "run.mcap")) << o.output;
    return d;
  }();
  return dir;
}

TEST(RunLog, TheOfficialReaderReadsTheRunsLogWithEveryTopic) {
  const fs::path log = logged_run() / "run.mcap";
  ASSERT_TRUE(fs::exists(log));
  const std::string modules = (fs::current_path() / "mcap-validator" / "node_modules").string();
  ASSERT_TRUE(fs::exists(fs::path(modules) / "@mcap" / "core"))
      << "the official MCAP reader is needed: run ./paddock test, which installs it into <build>/mcap-validator";
  const testing::Outcome o = testing::run_paddock_command("NODE_PATH='" + modules + "' node '" + kRoot +
                                                          "/tests/log/validate_mcap.mjs' '" + log.string() + "' 2>&1");
  ASSERT_EQ(o.code, 0) << o.output;
  const nlohmann::json j = nlohmann::json::parse(o.output);
  const nlohmann::json& topics = j.at("topics");
  // what the run lasted (its summary): the messages each sensor and cycle makes in that time
  std::ifstream summary(logged_run() / "summary.json");
  const double t = nlohmann::json::parse(summary).at("sim_time").get<double>();
  const long cycles = std::lround(t * 100.0) + 1, rotations = std::lround(std::floor(t * 10.0 + 1e-9));
  EXPECT_GT(t, 11.9);
  EXPECT_EQ(j.at("last_log_time").get<double>(), std::round(t * 1e9));
  // 64 packets a rotation; a cloud every fifth; a command and its frame each cycle
  EXPECT_EQ(topics.at("/lidar/packets").get<long>(), 64 * rotations);
  EXPECT_EQ(topics.at("/lidar/points").get<long>(), (rotations + 4) / 5);
  EXPECT_EQ(topics.at("/stack/command").get<long>(), cycles);
  EXPECT_EQ(topics.at("/can/tx").get<long>(), cycles);
  // the IMU's two frames at 200 Hz, wheels and steering at 100 Hz, the VCU's
  // status at 50 Hz, the RES's go
  EXPECT_EQ(topics.at("/can/rx").get<long>(), 2 * (2 * cycles - 1) + cycles + cycles + (cycles + 1) / 2 + 1);
  EXPECT_EQ(topics.at("/hal/detections").get<long>(), rotations);
  EXPECT_EQ(topics.at("/camera/image").get<long>(), rotations);  // the LiDAR triggers the camera once a rotation
  for (const char* topic : {"/tf", "/stack/pose", "/truth/pose", "/stack/map", "/stack/path", "/truth/cones"})
    EXPECT_GT(topics.at(topic).get<long>(), 0) << topic;
  for (const char* s : {"foxglove.FrameTransform", "foxglove.PoseInFrame", "foxglove.SceneUpdate", "foxglove.PointCloud",
                        "foxglove.CompressedImage"}) {
    bool found = false;
    for (const auto& name : j.at("schemas")) found = found || name.get<std::string>() == s;
    EXPECT_TRUE(found) << s;
  }
  // our own reader: the attachments a replay needs
  log::McapReader reader(std::make_unique<log::FileSource>(log.string()));
  reader.open();
  std::map<std::string, std::size_t> attached;
  for (const log::Attachment& a : reader.read_attachments()) attached[a.name] = a.data.size();
  for (const char* n : {"scenario.ini", "track.csv", "car.dbc", "lidar_metadata.json"}) EXPECT_GT(attached[n], 0u) << n;
}

TEST(RunLog, TheReplayGivesTheLiveRunsCommandsBitForBit) {
  const fs::path log = logged_run() / "run.mcap";
  const testing::Outcome same = testing::run_paddock("replay " + log.string());
  ASSERT_EQ(same.code, 0) << same.output;
  EXPECT_NE(same.output.find("compared with the log: all identical, bit for bit"), std::string::npos)
      << same.output;
  EXPECT_NE(same.output.find("final AS state driving"), std::string::npos) << same.output;
  // on two threads (the log read, and the LiDAR pipeline run, ahead of the
  // stack): the same commands, every scan's pipeline run on one or the other
  const testing::Outcome two = testing::run_paddock("replay " + log.string() + " --threads 2");
  ASSERT_EQ(two.code, 0) << two.output;
  EXPECT_NE(two.output.find("compared with the log: all identical, bit for bit"), std::string::npos) << two.output;
  std::smatch scans, split;
  ASSERT_TRUE(std::regex_search(two.output, scans, std::regex(R"(s: (\d+) LiDAR scans)"))) << two.output;
  ASSERT_TRUE(std::regex_search(two.output, split,
                                std::regex(R"(the LiDAR pipeline of (\d+) scans ran ahead on the second thread, (\d+) on)"))) << two.output;
  EXPECT_GT(std::stol(scans[1]), 50);
  EXPECT_EQ(std::stol(split[1]) + std::stol(split[2]), std::stol(scans[1])) << two.output;
  // a changed stack on the same log: it steers otherwise from the go on
  const testing::Outcome changed = testing::run_paddock("replay " + log.string() + " --set control.stanley.k=3");
  ASSERT_EQ(changed.code, 0) << changed.output;
  // (the go: 5 s after the car showed AS Ready at 0.5 s)
  EXPECT_NE(changed.output.find("the first difference at 5.500 s"), std::string::npos) << changed.output;
  // a window: the first 6 s only, profiled (the same commands)
  const testing::Outcome head = testing::run_paddock("replay " + log.string() + " --until 6 --profile");
  EXPECT_NE(head.output.find("601 compared with the log: all identical"), std::string::npos) << head.output;
  EXPECT_NE(head.output.find("where the wall time went (--profile):"), std::string::npos) << head.output;
  for (const char* stage : {"| logging |", "| lidar |", "| perception |", "| localisation |", "| planning |", "| total |"})
    EXPECT_NE(head.output.find(stage), std::string::npos) << stage << "\n" << head.output;
}

TEST(RunLog, ALogNeedsTheWireAndAReplayNeedsALog) {
  const testing::Outcome memory = testing::run_paddock("run " + kRoot + "/scenarios/fsg_2023_autocross.ini --log --out " +
                                                       (fs::temp_directory_path() / "paddock_no_wire").string());
  EXPECT_EQ(memory.code, 2);
  EXPECT_NE(memory.output.find("--log records the car's wires: it needs [hal] transport = wire"), std::string::npos)
      << memory.output;
  const testing::Outcome not_mcap = testing::run_paddock("replay " + kRoot + "/scenarios/sensors/paddock.dbc");
  EXPECT_EQ(not_mcap.code, 2);
  EXPECT_NE(not_mcap.output.find("paddock.dbc: mcap: byte 0: expected the Magic"), std::string::npos) << not_mcap.output;
  // cut short (an MCAP file without its summary): the byte named, nothing replayed
  const fs::path cut = fs::temp_directory_path() / ("paddock_cut_" + std::to_string(::getpid()) + ".mcap");
  {
    std::vector<std::uint8_t> bytes;
    log::McapWriter w(std::make_unique<log::MemorySink>(bytes));
    const std::uint16_t ch = w.add_channel(0, "/can/rx", "socketcan.can_frame");
    const std::uint8_t frame[16] = {};
    for (std::uint32_t i = 0; i < 100; ++i) w.write(ch, i, 1000u * i, 1000u * i, frame, sizeof frame);
    w.close();
    std::FILE* out = std::fopen(cut.c_str(), "wb");
    ASSERT_TRUE(out);
    std::fwrite(bytes.data(), 1, bytes.size() / 2, out);
    std::fclose(out);
  }
  const testing::Outcome short_log = testing::run_paddock("replay " + cut.string());
  EXPECT_EQ(short_log.code, 2);
  EXPECT_NE(short_log.output.find("cut short or damaged"), std::string::npos) << short_log.output;
  const testing::Outcome bad_time = testing::run_paddock("replay " + cut.string() + " --from -3");
  EXPECT_NE(bad_time.output.find("--from -3: expected a time in seconds >= 0"), std::string::npos) << bad_time.output;
}

// a log of the logged run's attachments (no messages), some replaced or added
fs::path log_with(const std::string& name, const std::map<std::string, std::string>& changed) {
  log::McapReader reader(std::make_unique<log::FileSource>((logged_run() / "run.mcap").string()));
  reader.open();
  std::map<std::string, std::vector<std::uint8_t>> files;
  for (const log::Attachment& a : reader.read_attachments()) files[a.name] = a.data;
  for (const auto& [n, text] : changed) files[n] = std::vector<std::uint8_t>(text.begin(), text.end());
  const fs::path out = fs::temp_directory_path() / ("paddock_" + name + "_" + std::to_string(::getpid()) + ".mcap");
  log::McapWriter w(std::make_unique<log::FileSink>(out.string()));
  for (const auto& [n, data] : files) w.write_attachment({0, 0, n, "text/plain", data});
  w.close();
  return out;
}

TEST(RunLog, AReplayWritesNothingAndReadsOnlyTheLogAndWhatTheUserNames) {
  // attachment names that would escape a folder, and a scenario that names a
  // file of its own: nothing is written, nothing but the log is read
  const fs::path escape = fs::temp_directory_path() / ("paddock_escaped_" + std::to_string(::getpid()));
  fs::remove(escape);
  const fs::path hostile = log_with("hostile", {{"../../../../../../" + escape.string(), "written?"}, {escape.string(), "written?"}});
  const testing::Outcome ok = testing::run_paddock("replay " + hostile.string() + " --until 6");
  EXPECT_EQ(ok.code, 0) << ok.output;
  EXPECT_NE(ok.output.find("1 control cycles"), std::string::npos) << ok.output;  // a log of attachments only
  EXPECT_FALSE(fs::exists(escape)) << "a log's attachment name wrote a file";
  // the log's scenario may include nothing
  log::McapReader reader(std::make_unique<log::FileSource>((logged_run() / "run.mcap").string()));
  reader.open();
  std::string ini;
  for (const log::Attachment& a : reader.read_attachments())
    if (a.name == "scenario.ini") ini.assign(a.data.begin(), a.data.end());
  ASSERT_FALSE(ini.empty());
  const fs::path including = log_with("including", {{"scenario.ini", "include = /etc/hostname\n" + ini}});
  const testing::Outcome inc = testing::run_paddock("replay " + including.string());
  EXPECT_EQ(inc.code, 2) << inc.output;
  EXPECT_NE(inc.output.find(including.string() + "/scenario.ini:1: include is not allowed here"), std::string::npos)
      << inc.output;
  // an error in an attachment is named by the log and the attachment
  const fs::path bad_track = log_with("bad_track", {{"track.csv", "x,y,color\n1,2,purple\n"}});
  const testing::Outcome bt = testing::run_paddock("replay " + bad_track.string());
  EXPECT_EQ(bt.code, 2) << bt.output;
  EXPECT_NE(bt.output.find(bad_track.string() + "/track.csv"), std::string::npos) << bt.output;
  // an attachment over the 64 MiB a replay reads is refused before it is read
  const fs::path huge = log_with("huge", {{"big.bin", std::string(64u * 1024u * 1024u + 1u, 'x')}});
  const testing::Outcome h = testing::run_paddock("replay " + huge.string());
  EXPECT_EQ(h.code, 2) << h.output;
  EXPECT_NE(h.output.find("attachment big.bin of 67108865 bytes, more than the 67108864 a replay reads: refused"),
            std::string::npos)
      << h.output;
  for (const fs::path& f : {hostile, including, bad_track, huge}) fs::remove(f);
}

}  // namespace
}  // namespace paddock::runner
