// paddock tune: issue 12's acceptance case as a user runs it (from a
// deliberately bad speed loop back to within 2 % of the shipped tuning's
// total time on FSG 2023 with no cone hit, each figure checked by a plain
// `paddock run` of its own), the best.ini it writes reproducing its best
// evaluation, and file:line errors for bad tune files.
#include "sim/runner/tune.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "sim/runner/files.h"
#include "tests/runner/run_paddock.h"

namespace paddock::runner {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

const std::string kRoot = PADDOCK_SOURCE_DIR;

std::string scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / "paddock_tune_test" / name;
  fs::remove_all(d);
  fs::create_directories(d.parent_path());
  return d.string();
}

// a number of summary.json's text
double json_number(const std::string& json, const std::string& key) {
  std::smatch m;
  if (!std::regex_search(json, m, std::regex("\"" + key + "\":(-?[0-9.eE+-]+)"))) return NAN;
  return std::stod(m[1]);
}

// the oracle run of FSG 2023 autocross with the paper's stack (the tune
// file's) and `sets`, as a user runs it
struct Plain {
  double total = NAN;
  int doo = -1;
  bool finished = false;
};
Plain plain_run(const std::string& sets, const std::string& name) {
  const auto o = testing::run_paddock("run " + testing::with_paper(kRoot + "/scenarios/fsg_2023_autocross.ini") +
                                      " --set autonomy.planner=oracle "
                                      "--set autonomy.perception=ground_truth --set autonomy.slam=ground_truth " +
                                      sets + " --json --out " + scratch(name));
  Plain p;
  if (o.code != 0) {
    ADD_FAILURE() << o.output;
    return p;
  }
  p.total = json_number(o.output, "total_time");
  p.doo = static_cast<int>(json_number(o.output, "doo"));
  p.finished = o.output.find("\"finished\":true") != std::string::npos;
  return p;
}

TEST(Tune, FromABadSpeedLoopBackWithinTwoPercentOfTheShippedTuning) {
  const std::string dir = scratch("acceptance");
  const auto t = testing::run_paddock("tune " + kRoot + "/scenarios/tunes/longitudinal_from_bad.ini --out " + dir);
  ASSERT_EQ(t.code, 0) << t.output;
  // the shipped tuning and the bad start, run here
  const Plain shipped = plain_run("", "shipped");
  const Plain bad = plain_run("--set control.longitudinal.kp=0.5 --set control.longitudinal.ki=0 "
                              "--set control.longitudinal.feedforward_gain=0.5",
                              "bad");
  ASSERT_TRUE(shipped.finished && bad.finished);
  EXPECT_GT(bad.total, 1.05 * shipped.total) << "the start is not bad enough to show anything";
  // the best values, read back from best.ini, run here
  const std::string best = read_file(dir + "/best.ini");
  std::string sets;
  for (const char* key : {"kp", "ki", "feedforward_gain"}) {
    std::smatch m;
    ASSERT_TRUE(std::regex_search(best, m, std::regex(std::string("\n") + key + " = ([^ ]+)"))) << best;
    sets += std::string(" --set control.longitudinal.") + key + "=" + m[1].str();
  }
  const Plain tuned = plain_run(sets, "tuned");
  ASSERT_TRUE(tuned.finished);
  std::printf("FSG 2023 autocross, oracle: shipped %.3f s, bad start %.3f s, tuned %.3f s (%d DOO)\n", shipped.total,
              bad.total, tuned.total, tuned.doo);
  EXPECT_LE(tuned.total, 1.02 * shipped.total);
  EXPECT_EQ(tuned.doo, 0);
  // and best.ini's objective is that run's cost: total + 10 x tracking RMS
  std::smatch m;
  ASSERT_TRUE(std::regex_search(best, m, std::regex("objective ([0-9.]+) against")));
  EXPECT_GE(std::stod(m[1]), tuned.total);
  EXPECT_LT(std::stod(m[1]), tuned.total + 10.0 * 0.5);
  EXPECT_THAT(read_file(dir + "/evaluations.csv"), HasSubstr("eval,control.longitudinal.kp,control.longitudinal.ki"));
}

std::string tune_error(const std::string& text) {
  const fs::path d = fs::temp_directory_path() / "paddock_tune_test" / "files";
  fs::create_directories(d);
  const std::string path = (d / "bad.ini").string();
  std::ofstream(path) << text;
  const auto o = testing::run_paddock("tune " + path + " --out " + scratch("bad"));
  EXPECT_EQ(o.code, 2) << o.output;
  return o.output;
}

TEST(Tune, BadFilesAreFileLineErrors) {
  const std::string head = "[tune]\nscenarios = " + kRoot + "/scenarios/acceleration.ini\n";
  EXPECT_THAT(tune_error(head + "[optimise]\ncontrol.stanley.k = bounds(2, 1)\n"), HasSubstr("bad.ini:4: [optimise] control.stanley.k: expected low < high"));
  EXPECT_THAT(tune_error(head + "[optimise]\ncontrol.stanley.k = logbounds(0, 1)\n"), HasSubstr("bad.ini:4: [optimise] control.stanley.k: expected 0 < low < high"));
  EXPECT_THAT(tune_error(head + "[optimise]\ncontrol.stanley.k = 1..3\n"), HasSubstr("bad.ini:4: [optimise] control.stanley.k: expected bounds(low, high)"));
  EXPECT_THAT(tune_error(head + "algorithm = lbfgs\n[optimise]\ncontrol.stanley.k = bounds(1, 3)\n"), HasSubstr("bad.ini:3: [tune] algorithm: expected sbplx"));
  EXPECT_THAT(tune_error(head + "max_evals = 2.5\n[optimise]\ncontrol.stanley.k = bounds(1, 3)\n"), HasSubstr("bad.ini:3: [tune] max_evals: expected a whole number"));
  EXPECT_THAT(tune_error(head + "weights = 1, 2\n[optimise]\ncontrol.stanley.k = bounds(1, 3)\n"), HasSubstr("bad.ini:3: [tune] weights: expected one per scenario (1), got 2"));
  EXPECT_THAT(tune_error(head), HasSubstr("no [optimise] keys"));
  // a key the scenario does not know, or that is no number, on its own line
  EXPECT_THAT(tune_error(head + "[optimise]\ncontrol.stanly.k = bounds(1, 3)\n"), HasSubstr("bad.ini:4: [optimise] control.stanly.k is not a scenario key"));
  EXPECT_THAT(tune_error(head + "[optimise]\ncontrol.lateral = bounds(1, 3)\n"), HasSubstr("bad.ini:4: [optimise] control.lateral is no number in the scenario (it has 'combined')"));
}

}  // namespace
}  // namespace paddock::runner
