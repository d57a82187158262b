// files: a result is never half-written (killed mid-run at many instants,
// every file of the run's folder reads whole, and the folder says it is
// incomplete); a full disk (here the file size limit, which fails a write
// the same way), an unwritable folder, a folder where a file is expected and
// an oversized input each give a clear error; Ctrl-C leaves the folder marked
// incomplete; a track of too many cones is refused at its first cone too many
#include "sim/runner/files.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>

#include "sim/runner/scenario.h"
#include "sim/world/track.h"
#include "tests/runner/background.h"
#include "tests/runner/run_paddock.h"

namespace paddock::runner {
namespace {

namespace fs = std::filesystem;

const std::string kRoot = PADDOCK_SOURCE_DIR;

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("paddock_files_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

TEST(Files, AFullDiskFailsTheWriteAndLeavesTheOldFileWhole) {
  const fs::path d = fresh_dir("full");
  const std::string p = (d / "summary.json").string();
  write_file_atomic(p, "{\"old\": true}\n");
  // a child whose files may not grow past 1 KiB: its write fails as on a full disk
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::signal(SIGXFSZ, SIG_IGN);
    const rlimit lim{1024, 1024};
    ::setrlimit(RLIMIT_FSIZE, &lim);
    try {
      write_file_atomic(p, std::string(100000, 'x'));
    } catch (const UserError& e) {
      const std::string what = e.what();
      ::_exit(what.find(p + ": cannot write: File too large") != std::string::npos ? 0 : 2);
    }
    ::_exit(1);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "1: the write succeeded; 2: another message";
  EXPECT_EQ(read_file(p), "{\"old\": true}\n");
  for (const fs::directory_entry& e : fs::directory_iterator(d)) EXPECT_EQ(e.path().filename(), "summary.json");
}

TEST(Files, AnUnwritableFolderAndAFolderForAFileAreNamed) {
  try {
    write_file_atomic("/etc/passwd/x/summary.json", "{}");
    ADD_FAILURE() << "written";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot create folder /etc/passwd/x: Not a directory"), std::string::npos) << e.what();
  }
  const fs::path d = fresh_dir("folder");
  try {
    read_file(d.string());
    ADD_FAILURE() << "read";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("it is a folder, expected a file"), std::string::npos) << e.what();
  }
  const std::string big = (d / "big.csv").string();
  write_file_atomic(big, std::string(5000, 'x'));
  try {
    read_file(big, 4096);
    ADD_FAILURE() << "read";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("5000 bytes, more than the 4096"), std::string::npos) << e.what();
  }
}

TEST(Files, ATrackOfTooManyConesIsRefusedAtTheConeTooMany) {
  std::ostringstream t;
  t << "tag,x,y\n";
  for (std::size_t i = 0; i <= world::kMaxTrackCones; ++i) t << "blue," << i << ",1.5\n";
  const auto t0 = std::chrono::steady_clock::now();
  try {
    world::parse_track(t.str(), "huge.csv");
    ADD_FAILURE() << "parsed";
  } catch (const world::TrackError& e) {
    EXPECT_NE(std::string(e.what()).find("huge.csv:" + std::to_string(world::kMaxTrackCones + 2) + ": more than 10000 cones"),
              std::string::npos)
        << e.what();
  }
  // refused before the quadratic check for doubled cones could run
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
}

// every result file of a run's folder reads whole: the JSON parses, the CSV
// ends its last row, the resolved scenario loads
void expect_whole(const fs::path& dir, const std::string& when) {
  for (const fs::directory_entry& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name.find(".tmp.") != std::string::npos) continue;  // a write the kill cut short, never renamed into place
    const std::string text = read_file(e.path().string());
    if (name.size() > 5 && name.substr(name.size() - 5) == ".json") {
      EXPECT_FALSE(nlohmann::json::parse(text, nullptr, false).is_discarded()) << name << " " << when;
    } else if (name.size() > 4 && name.substr(name.size() - 4) == ".csv") {
      EXPECT_TRUE(!text.empty() && text.back() == '\n') << name << " " << when;
    } else if (name == "scenario.ini") {
      EXPECT_NO_THROW(load_scenario(e.path().string())) << when;
    }
  }
}

TEST(Files, ARunKilledAtAnyInstantLeavesWholeFilesAndSaysItIsIncomplete) {
  const std::string scenario = kRoot + "/scenarios/ci/oracle_acceleration.ini";
  const fs::path d = fresh_dir("killed");
  // a complete run first: its files are the old ones the killed runs find
  const auto t0 = std::chrono::steady_clock::now();
  const testing::Outcome whole = testing::run_paddock("run " + scenario + " --quiet --out " + d.string());
  const double full = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_EQ(whole.code, 0) << whole.output;
  EXPECT_FALSE(fs::exists(d / "INCOMPLETE"));
  expect_whole(d, "after a complete run");
  // the folder's files as they are (name, size, time written)
  const auto files = [&d] {
    std::map<std::string, std::pair<std::uintmax_t, fs::file_time_type>> f;
    for (const fs::directory_entry& e : fs::directory_iterator(d)) {
      if (e.is_regular_file()) f[e.path().filename().string()] = {e.file_size(), e.last_write_time()};
    }
    return f;
  };
  for (int k = 1; k <= 8; ++k) {
    const double at = full * k / 8.0;  // through the run and its writes at the end
    const auto before = files();
    testing::Background run("run " + scenario + " --quiet --out " + d.string());
    std::this_thread::sleep_for(std::chrono::duration<double>(at));
    run.signal(SIGKILL);
    const int code = run.wait(60.0);
    const std::string when = "killed after " + std::to_string(at) + " s";
    expect_whole(d, when);
    // killed before it was done, the folder says so; done, it does not.
    // Killed before it began on the folder (loading its scenario and track
    // on a loaded machine), it left the folder as it was: nothing written
    if (code != 0 && !fs::exists(d / "INCOMPLETE")) {
      EXPECT_EQ(files(), before) << when << ": killed without its marker, yet the folder changed";
    } else {
      EXPECT_EQ(fs::exists(d / "INCOMPLETE"), code != 0) << when;
    }
  }
}

TEST(Files, CtrlCLeavesTheRunsFolderMarkedIncomplete) {
  const fs::path d = fresh_dir("interrupted");
  testing::Background run("run " + kRoot + "/scenarios/ci/fsg_2023_autocross.ini --out " + d.string());
  // wait for the folder's marker, then Ctrl-C in the middle of the run
  for (int i = 0; i < 600 && !fs::exists(d / "INCOMPLETE"); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  ASSERT_TRUE(fs::exists(d / "INCOMPLETE"));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  run.signal(SIGINT);
  EXPECT_EQ(run.wait(60.0), 128 + SIGINT) << run.output();
  EXPECT_NE(run.output().find("paddock: interrupted; " + (d / "INCOMPLETE").string() + " marks the run's folder incomplete"),
            std::string::npos)
      << run.output();
  EXPECT_TRUE(fs::exists(d / "INCOMPLETE"));
  EXPECT_NE(read_file((d / "INCOMPLETE").string()).find("interrupted or failed"), std::string::npos);
  EXPECT_FALSE(fs::exists(d / "summary.json"));
}

}  // namespace
}  // namespace paddock::runner
