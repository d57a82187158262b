// paddock bench compare: ratios of two benchmark runs against hand-computed
// ones, the flag at 10 %, aggregates, and the files it must refuse.
#include "sim/runner/bench_compare.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <unistd.h>

#include "sim/runner/cli.h"
#include "sim/runner/files.h"

namespace paddock::runner {
namespace {

std::string scratch_file(const std::string& name, const std::string& content) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("paddock_bench_compare_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / name).string();
  write_file_atomic(path, content);
  return path;
}

// one plain run per benchmark: name, cpu time, unit
std::string bench_json(const std::vector<std::tuple<std::string, double, std::string>>& runs) {
  std::string s = "{\n  \"context\": {\"num_cpus\": 2},\n  \"benchmarks\": [\n";
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const auto& [name, cpu, unit] = runs[i];
    s += "    {\"name\": \"" + name + "\", \"run_name\": \"" + name +
         "\", \"run_type\": \"iteration\", \"iterations\": 10, \"real_time\": " + std::to_string(cpu * 1.01) +
         ", \"cpu_time\": " + std::to_string(cpu) + ", \"time_unit\": \"" + unit + "\"}";
    s += i + 1 < runs.size() ? ",\n" : "\n";
  }
  return s + "  ]\n}\n";
}

TEST(BenchCompare, RatiosPerBenchmarkAndTheTenPercentFlag) {
  const std::string old_path = scratch_file(
      "old.json", bench_json({{"BM_A", 100.0, "ns"}, {"BM_B", 2.0, "us"}, {"BM_C", 1.0, "ms"}, {"BM_D", 3.0, "ms"}}));
  const std::string new_path = scratch_file(
      "new.json", bench_json({{"BM_B", 2400.0, "ns"}, {"BM_A", 105.0, "ns"}, {"BM_D", 0.0033, "s"}, {"BM_E", 1.0, "us"}}));
  const BenchComparison c = compare_benchmarks(read_bench_json(old_path), read_bench_json(new_path));
  ASSERT_EQ(c.rows.size(), 3u);
  // NEW's order; units converted: 2.4 us / 2 us, 105 / 100 ns, 3.3 ms / 3 ms
  EXPECT_EQ(c.rows[0].name, "BM_B");
  EXPECT_NEAR(c.rows[0].ratio, 1.2, 1e-12);
  EXPECT_TRUE(c.rows[0].slower);
  EXPECT_NEAR(c.rows[1].ratio, 1.05, 1e-12);
  EXPECT_FALSE(c.rows[1].slower);
  EXPECT_NEAR(c.rows[2].ratio, 1.1, 1e-9);
  EXPECT_FALSE(c.rows[2].slower);  // exactly 10 % is not more than 10 %
  EXPECT_EQ(c.slower, 1);
  EXPECT_EQ(c.only_old, std::vector<std::string>{"BM_C"});
  EXPECT_EQ(c.only_new, std::vector<std::string>{"BM_E"});
  const std::string text = bench_comparison_text(c);
  EXPECT_NE(text.find("BM_B"), std::string::npos);
  EXPECT_NE(text.find("1.200  SLOWER"), std::string::npos) << text;
  EXPECT_EQ(text.find("SLOWER"), text.rfind("SLOWER")) << text;
  EXPECT_NE(text.find("1 of 3 benchmarks more than 10 % slower"), std::string::npos) << text;
  // the command: exit 1 with a slower one, 0 without
  EXPECT_EQ(run_cli({"bench-compare", old_path, new_path}), 1);
  EXPECT_EQ(run_cli({"bench-compare", old_path, old_path}), 0);
}

TEST(BenchCompare, RepeatedRunsAreComparedByTheirMedian) {
  const std::string agg = R"({"benchmarks": [
    {"name": "BM_X/repeats:3", "run_name": "BM_X", "run_type": "iteration", "real_time": 9, "cpu_time": 9, "time_unit": "us"},
    {"name": "BM_X/repeats:3_mean", "run_name": "BM_X", "run_type": "aggregate", "aggregate_name": "mean", "real_time": 12, "cpu_time": 12, "time_unit": "us"},
    {"name": "BM_X/repeats:3_median", "run_name": "BM_X", "run_type": "aggregate", "aggregate_name": "median", "real_time": 10, "cpu_time": 10, "time_unit": "us"}
  ]})";
  const std::vector<BenchTiming> t = read_bench_json(scratch_file("agg.json", agg));
  ASSERT_EQ(t.size(), 1u);
  EXPECT_EQ(t[0].name, "BM_X");
  EXPECT_DOUBLE_EQ(t[0].cpu_ns, 10000.0);
}

TEST(BenchCompare, BadFilesAreNamedWithWhatWasExpected) {
  const auto error_of = [](const std::string& path) {
    try {
      read_bench_json(path);
    } catch (const UserError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const std::string broken = scratch_file("broken.json", "{\n  \"benchmarks\": [\n    {\"name\": \n");
  EXPECT_NE(error_of(broken).find(broken + ":4: not JSON"), std::string::npos) << error_of(broken);
  const std::string no_list = scratch_file("no_list.json", "{\"context\": {}}\n");
  EXPECT_NE(error_of(no_list).find("\"benchmarks\" array"), std::string::npos) << error_of(no_list);
  const std::string unit = scratch_file("unit.json", bench_json({{"BM_A", 1.0, "fortnights"}}));
  EXPECT_NE(error_of(unit).find("time unit 'fortnights'"), std::string::npos) << error_of(unit);
  const std::string no_time = scratch_file("no_time.json", R"({"benchmarks": [{"name": "BM_A", "real_time": 1}]})");
  EXPECT_NE(error_of(no_time).find("without \"cpu_time\""), std::string::npos) << error_of(no_time);
  EXPECT_NE(error_of("/nonexistent/old.json").find("/nonexistent/old.json"), std::string::npos);
  EXPECT_EQ(run_cli({"bench-compare", "/nonexistent/old.json", unit}), 2);
  EXPECT_EQ(run_cli({"bench-compare", unit}), 2);
}

}  // namespace
}  // namespace paddock::runner
