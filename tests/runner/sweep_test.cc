// paddock sweep: the sweep file's values and points against their
// definitions (computed here), a Latin hypercube's strata by brute force,
// file:line errors, and the command as a user runs it: the same results.csv
// whatever the number of jobs, every row the figures of a plain `paddock run`
// of the point's own resolved scenario, and --resume running only what is
// missing.
#include "sim/runner/sweep.h"
#include "sim/runner/sweep_report.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "sim/runner/files.h"
#include "tests/runner/run_paddock.h"

namespace paddock::runner {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

const std::string kRoot = PADDOCK_SOURCE_DIR;

std::string scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / "paddock_sweep_test" / name;
  fs::remove_all(d);
  fs::create_directories(d.parent_path());
  return d.string();
}

// a sweep file in a scratch folder, naming scenarios by absolute path
std::string sweep_file(const std::string& name, const std::string& text) {
  const fs::path d = fs::temp_directory_path() / "paddock_sweep_test" / "files";
  fs::create_directories(d);
  const std::string path = (d / (name + ".ini")).string();
  std::ofstream(path) << text;
  return path;
}

std::string expect_error(const std::string& text) {
  const std::string path = sweep_file("bad", text);
  try {
    const SweepSpec spec = load_sweep(path);
    const auto points = expand_sweep(spec);
    for (const auto& p : points) sweep_point_scenario(spec, p);
  } catch (const UserError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no error for:\n" << text;
  return "";
}

const std::string kAcc = "scenarios = " + kRoot + "/scenarios/acceleration.ini\n";

TEST(Sweep, ValuesFollowTheirDefinitions) {
  const SweepSpec s = load_sweep(sweep_file("values", "[sweep]\n" + kAcc +
                                                          "[vary]\n"
                                                          "control.stanley.k = linspace(0.5, 2, 4)\n"
                                                          "control.combined.kappa_ref = logspace(0.01, 1, 3)\n"
                                                          "event.timeout = 100..103\n"
                                                          "control.lateral = stanley,  combined\n"));
  ASSERT_EQ(s.axes.size(), 4u);
  EXPECT_EQ(s.axes[0].values, (std::vector<std::string>{"0.5", "1", "1.5", "2"}));
  // geometric, the ends exact: 0.01, 0.1, 1 (the middle to a few ulp)
  ASSERT_EQ(s.axes[1].values.size(), 3u);
  EXPECT_EQ(s.axes[1].values[0], "0.01");
  EXPECT_NEAR(std::stod(s.axes[1].values[1]), 0.1, 1e-15);
  EXPECT_EQ(s.axes[1].values[2], "1");
  EXPECT_EQ(s.axes[2].values, (std::vector<std::string>{"100", "101", "102", "103"}));
  EXPECT_EQ(s.axes[3].values, (std::vector<std::string>{"stanley", "combined"}));
  EXPECT_EQ(s.axes[3].where.line, 7);
}

TEST(Sweep, GridZipAndSeedsGiveEveryPointOnceInOrder) {
  const std::string head = "[sweep]\nscenarios = " + kRoot + "/scenarios/acceleration.ini, " + kRoot +
                           "/scenarios/skidpad.ini\nseeds = 3..4\n";
  const SweepSpec g = load_sweep(sweep_file("grid", head + "[vary]\ncontrol.stanley.k = 1, 2, 3\ncontrol.lateral = stanley, combined\n"));
  const auto pg = expand_sweep(g);
  // scenarios x (3 x 2) x seeds, scenario slowest, then the first key, the seed fastest
  ASSERT_EQ(pg.size(), 2u * 6u * 2u);
  std::set<std::tuple<std::size_t, std::string, std::string, std::uint64_t>> seen;
  for (std::size_t i = 0; i < pg.size(); ++i) {
    const SweepPoint& p = pg[i];
    EXPECT_EQ(p.index, static_cast<int>(i));
    EXPECT_EQ(p.scenario, i / 12);
    EXPECT_EQ(p.values[0], std::to_string(i / 4 % 3 + 1));
    EXPECT_EQ(p.values[1], i / 2 % 2 == 0 ? "stanley" : "combined");
    ASSERT_TRUE(p.seed.has_value());
    EXPECT_EQ(*p.seed, 3u + i % 2);
    seen.insert({p.scenario, p.values[0], p.values[1], *p.seed});
  }
  EXPECT_EQ(seen.size(), pg.size());

  const SweepSpec z = load_sweep(sweep_file("zip", "[sweep]\n" + kAcc + "combine = zip\n[vary]\ncontrol.stanley.k = 1, 2, 3\ncontrol.lateral = stanley, combined, pure_pursuit\n"));
  const auto pz = expand_sweep(z);
  ASSERT_EQ(pz.size(), 3u);
  EXPECT_EQ(pz[2].values, (std::vector<std::string>{"3", "pure_pursuit"}));
  EXPECT_FALSE(pz[0].seed.has_value());
  // the value reaches the scenario
  const Scenario sc = sweep_point_scenario(z, pz[1]);
  EXPECT_EQ(sc.control.stanley.k, 2.0);
  EXPECT_EQ(sc.control.lateral, control::LateralMode::Combined);
}

TEST(Sweep, LatinHypercubeDrawsEachStratumOnceRandomStaysInBounds) {
  const std::string text = "[sweep]\n" + kAcc +
                           "samples = 50\nsampling = lhs\nsample_seed = 9\n[vary]\n"
                           "control.stanley.k = uniform(1, 3)\ncontrol.combined.kappa_ref = loguniform(0.01, 1)\n";
  const SweepSpec s = load_sweep(sweep_file("lhs", text));
  const auto p = expand_sweep(s);
  ASSERT_EQ(p.size(), 50u);
  std::set<int> strata_k, strata_kappa;
  for (const SweepPoint& q : p) {
    const double k = std::stod(q.values[0]), kappa = std::stod(q.values[1]);
    // stratum of each draw: linear for uniform, in log for loguniform
    strata_k.insert(static_cast<int>(std::floor((k - 1.0) / 2.0 * 50.0)));
    strata_kappa.insert(static_cast<int>(std::floor((std::log(kappa) - std::log(0.01)) / (std::log(1.0) - std::log(0.01)) * 50.0)));
  }
  EXPECT_EQ(strata_k.size(), 50u) << "each of the 50 strata of k once";
  EXPECT_EQ(strata_kappa.size(), 50u);
  EXPECT_EQ(*strata_k.begin(), 0);
  EXPECT_EQ(*strata_k.rbegin(), 49);
  // the same seed draws the same values; another seed others
  EXPECT_EQ(expand_sweep(load_sweep(sweep_file("lhs2", text)))[7].values, p[7].values);
  std::string other = text;
  other.replace(other.find("sample_seed = 9"), 15, "sample_seed = 8");
  EXPECT_NE(expand_sweep(load_sweep(sweep_file("lhs3", other)))[7].values, p[7].values);

  std::string random = text;
  random.replace(random.find("sampling = lhs"), 14, "sampling = random");
  const auto r = expand_sweep(load_sweep(sweep_file("random", random)));
  ASSERT_EQ(r.size(), 50u);
  std::set<std::string> distinct;
  for (const SweepPoint& q : r) {
    const double k = std::stod(q.values[0]), kappa = std::stod(q.values[1]);
    EXPECT_GE(k, 1.0);
    EXPECT_LE(k, 3.0);
    EXPECT_GE(kappa, 0.01);
    EXPECT_LE(kappa, 1.0);
    distinct.insert(q.values[0]);
  }
  EXPECT_EQ(distinct.size(), 50u);
}

TEST(Sweep, BadFilesAreFileLineErrors) {
  EXPECT_THAT(expect_error("[sweep]\n" + kAcc + "[vary]\ncontrol.stanley.k = linspace(1, 2)\n"),
              HasSubstr("bad.ini:4: linspace(first, last, count) takes 3 numbers"));
  EXPECT_THAT(expect_error("[sweep]\n" + kAcc + "[vary]\ncontrol.stanley.k = logspace(0, 2, 3)\n"),
              HasSubstr("bad.ini:4: logspace(first, last, count): first and last must be > 0"));
  EXPECT_THAT(expect_error("[sweep]\n" + kAcc + "combine = product\n"), HasSubstr("bad.ini:3: combine: expected grid or zip"));
  EXPECT_THAT(expect_error("[sweep]\n" + kAcc + "seed = 1\n"), HasSubstr("bad.ini:3: [sweep] unknown key 'seed'"));
  EXPECT_THAT(expect_error("[sweep]\n" + kAcc + "seeds = 5..2\n"), HasSubstr("bad.ini:3: seeds: expected whole numbers"));
  EXPECT_THAT(expect_error("[sweep]\n" + kAcc + "[vary]\ncontrol.stanley.k = uniform(1, 2)\n"),
              HasSubstr("samples is not set"));
  EXPECT_THAT(expect_error("[sweep]\n" + kAcc + "combine = zip\n[vary]\ncontrol.stanley.k = 1, 2\ncontrol.lateral = stanley\n"),
              HasSubstr("bad.ini:6: combine = zip: control.lateral has 1 values, but control.stanley.k has 2"));
  // a value the scenario refuses is reported on its [vary] line
  EXPECT_THAT(expect_error("[sweep]\n" + kAcc + "[vary]\ncontrol.lateral = stanley, lqr\n"),
              HasSubstr("bad.ini:4: [control] lateral = 'lqr' is not known"));
  EXPECT_THAT(expect_error("[sweep]\n" + kAcc + "[vary]\ncontrol.stanly.k = 1\n"), HasSubstr("bad.ini:4: unknown section [control.stanly]"));
  EXPECT_THAT(expect_error("[sweep]\nscenarios = nowhere.ini\n"), HasSubstr("nowhere.ini"));
}

// ---- the command

std::string read(const std::string& p) { return read_file(p); }

std::vector<std::vector<std::string>> csv_rows(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string> r;
    std::stringstream ls(line);
    std::string c;
    while (std::getline(ls, c, ',')) r.push_back(c);
    if (!line.empty() && line.back() == ',') r.push_back("");
    rows.push_back(r);
  }
  return rows;
}

TEST(Sweep, SameResultsWhateverTheJobsAndEachRowIsAPlainRunsFigures) {
  // acceleration runs on the raw sensors and the full stack: 2 gains x 2 seeds
  const std::string f = sweep_file("acc", "[sweep]\n" + kAcc + "seeds = 1..2\n[vary]\ncontrol.longitudinal.kp = 1.5, 2.5\n");
  const std::string one = scratch("jobs1"), two = scratch("jobs2");
  const auto a = testing::run_paddock("sweep " + f + " --jobs 1 --out " + one);
  ASSERT_EQ(a.code, 0) << a.output;
  const auto b = testing::run_paddock("sweep " + f + " --jobs 2 --out " + two);
  ASSERT_EQ(b.code, 0) << b.output;
  const std::string table = read(one + "/results.csv");
  EXPECT_EQ(table, read(two + "/results.csv")) << "results.csv differs between --jobs 1 and --jobs 2";
  const auto rows = csv_rows(table);
  ASSERT_EQ(rows.size(), 5u);
  EXPECT_EQ(rows[0][2], "control.longitudinal.kp");
  EXPECT_EQ(rows[0][3], "seed");
  EXPECT_EQ(rows[0][10], "total_time_s");
  // point 3: kp 2.5, seed 2; its own scenario run by hand gives its row's figures
  EXPECT_EQ(rows[4][2], "2.5");
  EXPECT_EQ(rows[4][3], "2");
  const std::string point = two + "/points/0003";
  const std::string again = scratch("again");
  const auto c = testing::run_paddock("run " + point + "/scenario.ini --json --out " + again);
  ASSERT_EQ(c.code, 0) << c.output;
  EXPECT_THAT(c.output, HasSubstr("\"total_time\":" + rows[4][10]));
  EXPECT_EQ(rows[4][4], "true");
  // the seeds differ, so do the runs
  EXPECT_NE(rows[3][10] + rows[3][15], rows[4][10] + rows[4][15]);
}

TEST(Sweep, ResumeRunsOnlyWhatIsMissingAndRefusesAChangedSweep) {
  const std::string f = sweep_file("resume", "[sweep]\n" + kAcc + "[vary]\ncontrol.longitudinal.kp = 1.5, 2, 2.5\n");
  const std::string dir = scratch("resume");
  ASSERT_EQ(testing::run_paddock("sweep " + f + " --out " + dir).code, 0);
  const std::string full = read(dir + "/results.csv");
  const auto kept = fs::last_write_time(dir + "/points/0000/summary.json");
  fs::remove(dir + "/points/0001/summary.json");  // as if killed while running it
  const auto again = testing::run_paddock("sweep " + f + " --out " + dir);
  EXPECT_EQ(again.code, 2);
  EXPECT_THAT(again.output, HasSubstr("holds a sweep already: --resume"));
  const auto r = testing::run_paddock("sweep " + f + " --resume --out " + dir);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("1 of 1 points run"));
  EXPECT_EQ(fs::last_write_time(dir + "/points/0000/summary.json"), kept);
  EXPECT_EQ(read(dir + "/results.csv"), full);
  // the file changed under the folder: refused, not mixed
  fs::remove(dir + "/points/0002/summary.json");
  std::ofstream(f, std::ios::app) << "[control]\nlateral = stanley\n";
  const auto changed = testing::run_paddock("sweep " + f + " --resume --out " + dir);
  EXPECT_EQ(changed.code, 2);
  EXPECT_THAT(changed.output, HasSubstr("points/0000: this point's scenario differs"));
  std::ofstream(f) << "[sweep]\n" + kAcc + "[vary]\ncontrol.longitudinal.kp = 1.5, 2, 3\n";
  const auto values = testing::run_paddock("sweep " + f + " --resume --out " + dir);
  EXPECT_EQ(values.code, 2);
  EXPECT_THAT(values.output, HasSubstr("points.csv: its points differ"));
}

// ---- Slurm: a private single-node cluster (tools/slurm_private.sh: slurmctld,
// slurmd and munged on loopback, state in a temporary folder), started and
// stopped here; the sweep through it gives the local run's results.csv

struct PrivateSlurm {
  std::string dir, error;
  PrivateSlurm() {
    const std::string tool = kRoot + "/tools/slurm_private.sh";
    if (std::system((tool + " check >/dev/null 2>&1").c_str()) != 0) {
      error = "Slurm is not installed (Debian: slurm-wlm, munge; ./paddock test installs them)";
      return;
    }
    char tmpl[] = "/tmp/paddock_slurm_XXXXXX";
    if (!mkdtemp(tmpl)) {
      error = "cannot make a temporary folder";
      return;
    }
    dir = tmpl;
    // (a second try after a failed start: a loaded machine's timing, not a
    // persistent fault; both tries' logs are kept in the message)
    const std::string key = "export SLURM_CONF=";
    testing::Outcome o;
    std::string::size_type at = std::string::npos;
    for (int attempt = 0; attempt < 2 && at == std::string::npos; ++attempt) {
      o = testing::run_paddock_command(tool + " start " + dir + " 2>" + dir + "/start.log");
      at = o.code == 0 ? o.output.find(key) : std::string::npos;
      if (at == std::string::npos) {
        error += "the private Slurm did not start: " + o.output + read_file(dir + "/start.log");
        (void)std::system((tool + " stop " + dir + " >/dev/null 2>&1").c_str());
      }
    }
    if (at == std::string::npos) return;
    error.clear();
    const std::string conf = o.output.substr(at + key.size(), o.output.find('\n', at) - at - key.size());
    setenv("SLURM_CONF", conf.c_str(), 1);
  }
  ~PrivateSlurm() {
    if (dir.empty()) return;
    (void)std::system((kRoot + "/tools/slurm_private.sh stop " + dir + " >/dev/null 2>&1").c_str());
    unsetenv("SLURM_CONF");
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
};

TEST(Sweep, SlurmArrayJobGivesTheLocalResultsByteForByte) {
  if (geteuid() != 0) GTEST_SKIP() << "the private Slurm runs its daemons as root (SlurmUser=root)";
  const PrivateSlurm slurm;
  if (!slurm.error.empty() && slurm.error.rfind("Slurm is not installed", 0) == 0) GTEST_SKIP() << slurm.error;
  ASSERT_EQ(slurm.error, "");
  const std::string f = sweep_file("slurm", "[sweep]\n" + kAcc + "seeds = 1..2\n[vary]\ncontrol.longitudinal.kp = 1.5, 2.5\n");
  const std::string local = scratch("slurm_local"), cluster = scratch("slurm_cluster");
  const auto a = testing::run_paddock("sweep " + f + " --jobs 2 --out " + local);
  ASSERT_EQ(a.code, 0) << a.output;
  // three array tasks for four points (shards of 1, 1 and 2 points), waited for and collected
  const auto b = testing::run_paddock("sweep " + f + " --slurm --tasks 3 --wait --out " + cluster);
  ASSERT_EQ(b.code, 0) << b.output;
  EXPECT_THAT(b.output, HasSubstr("4 of 4 points done"));
  EXPECT_THAT(read(cluster + "/slurm/sweep.sbatch"), HasSubstr("#SBATCH --array=0-2"));
  for (int t = 0; t < 3; ++t) EXPECT_THAT(read(cluster + "/slurm/task_" + std::to_string(t) + ".out"), HasSubstr("shard " + std::to_string(t) + "/3"));
  EXPECT_EQ(read(cluster + "/results.csv"), read(local + "/results.csv"));
  // and collect again, by hand, gives the same
  fs::remove(cluster + "/results.csv");
  const auto c = testing::run_paddock("sweep collect " + cluster);
  ASSERT_EQ(c.code, 0) << c.output;
  EXPECT_EQ(read(cluster + "/results.csv"), read(local + "/results.csv"));
}

TEST(Sweep, ShardsSplitThePointsAndDryRunOnlyWritesTheScript) {
  // every point in exactly one shard, in order, sizes within one
  for (std::size_t p : {1u, 4u, 7u, 100u}) {
    for (int n : {1, 2, 3, 7}) {
      std::size_t next = 0, lo = p, hi = 0;
      for (int i = 0; i < n; ++i) {
        const auto [a, b] = sweep_shard(p, i, n);
        EXPECT_EQ(a, next);
        next = b;
        lo = std::min(lo, b - a);
        hi = std::max(hi, b - a);
      }
      EXPECT_EQ(next, p);
      EXPECT_LE(hi - lo, 1u);
    }
  }
  const std::string f = sweep_file("dry", "[sweep]\n" + kAcc + "[vary]\ncontrol.longitudinal.kp = 1, 2, 3\n");
  const std::string dir = scratch("dry");
  const auto o = testing::run_paddock("sweep " + f + " --slurm --dry-run --partition short --time 0:10:00 --array-limit 2 --out " + dir);
  ASSERT_EQ(o.code, 0) << o.output;
  const std::string script = read(dir + "/slurm/sweep.sbatch");
  EXPECT_THAT(script, HasSubstr("#SBATCH --array=0-2%2"));
  EXPECT_THAT(script, HasSubstr("#SBATCH --partition=short"));
  EXPECT_THAT(script, HasSubstr("#SBATCH --time=0:10:00"));
  EXPECT_THAT(script, HasSubstr("--shard \"$SLURM_ARRAY_TASK_ID/3\""));
  EXPECT_FALSE(fs::exists(dir + "/points/0000"));
  // a shard alone runs its slice only; collect names what is missing
  const auto s1 = testing::run_paddock("sweep " + f + " --shard 1/3 --out " + dir);
  ASSERT_EQ(s1.code, 0) << s1.output;
  EXPECT_TRUE(fs::exists(dir + "/points/0001/summary.json"));
  EXPECT_FALSE(fs::exists(dir + "/points/0000/summary.json"));
  const auto c = testing::run_paddock("sweep collect " + dir);
  EXPECT_EQ(c.code, 1);
  EXPECT_THAT(c.output, HasSubstr("2 points without a summary: 0, 2"));
  EXPECT_THAT(read(dir + "/results.csv"), HasSubstr(",not run\n"));
}

// ---- the report and the figures, from a results.csv written here

TEST(Sweep, ReportRanksConfigurationsOverEveryRunAndPlotsDraw) {
  const std::string dir = scratch("report");
  fs::create_directories(dir);
  // two keys; configuration (1, a) is fastest on track A but DNFs on B;
  // (2, a) wins on the mean; (2, b) is close behind with a cone
  std::string csv = "point,scenario,control.stanley.k,control.lateral,seed,finished,dnf_reason,laps,best_lap_s,mean_lap_s,"
                    "raw_time_s,total_time_s,doo,oc,uss,penalty_s,tracking_rms_m,tracking_max_m,itae,ate_rms_m,ate_max_m,"
                    "map_rmse_m,map_precision,map_recall,perception_precision,perception_recall,expectations_failed,error\n";
  const auto row = [&](int p, const char* sc, const char* k, const char* lat, bool fin, double total, int doo, double rms) {
    std::ostringstream o;
    o << p << "," << sc << "," << k << "," << lat << ",1," << (fin ? "true" : "false") << "," << (fin ? "" : "timeout")
      << ",1,,," << total << "," << total << "," << doo << ",0,0," << 2 * doo << "," << rms << ",,,,,,,,,,0,\n";
    csv += o.str();
  };
  row(0, "A", "1", "a", true, 30.0, 0, 0.1);
  row(1, "A", "1", "b", true, 31.0, 0, 0.1);
  row(2, "A", "2", "a", true, 30.5, 0, 0.05);
  row(3, "A", "2", "b", true, 30.6, 1, 0.07);
  row(4, "B", "1", "a", false, 0.0, 0, 0.0);
  row(5, "B", "1", "b", true, 41.0, 0, 0.1);
  row(6, "B", "2", "a", true, 40.5, 0, 0.05);
  row(7, "B", "2", "b", true, 40.6, 0, 0.06);
  write_file_atomic(dir + "/results.csv", csv);
  const SweepTable t = sweep_table(dir);
  ASSERT_EQ(t.keys, (std::vector<std::string>{"control.stanley.k", "control.lateral"}));
  ASSERT_EQ(t.configs.size(), 4u);
  // by the mean over both tracks: (2, a) 35.5, (2, b) 35.6, (1, b) 36.0, then (1, a) with a DNF
  EXPECT_EQ(t.configs[0].values, (std::vector<std::string>{"2", "a"}));
  EXPECT_DOUBLE_EQ(t.configs[0].mean_total, 35.5);
  EXPECT_DOUBLE_EQ(t.configs[0].worst_total, 40.5);
  EXPECT_EQ(t.configs[1].values, (std::vector<std::string>{"2", "b"}));
  EXPECT_EQ(t.configs[1].cones, 1);
  EXPECT_EQ(t.configs[2].values, (std::vector<std::string>{"1", "b"}));
  EXPECT_EQ(t.configs[3].values, (std::vector<std::string>{"1", "a"}));
  EXPECT_EQ(t.configs[3].finished, 1);
  const std::string md = sweep_report(t, 2);
  EXPECT_THAT(md, HasSubstr("| 1 | 2 | a | 2 / 2 | 35.500 | 40.500 | 0 | 0.050 | 2 |"));
  EXPECT_THAT(md, Not(HasSubstr("\n| 3 |")));
  EXPECT_THAT(md, HasSubstr("[control.stanley]\nk = 2\n\n[control]\nlateral = a\n"));
  // the figures: one per numeric key, the Pareto front (the heat map needs two numeric keys)
  const auto o = testing::run_paddock("sweep plot " + dir + " --chart-size 800x600");
  ASSERT_EQ(o.code, 0) << o.output;
  for (const char* f : {"/plots/total_time_control_stanley_k.png", "/plots/pareto.png"}) {
    const std::string png = read(dir + f);
    ASSERT_GT(png.size(), 1000u) << f;
    EXPECT_EQ(png.substr(1, 3), "PNG");
  }
  EXPECT_FALSE(fs::exists(dir + "/plots/heatmap.png"));
  EXPECT_FALSE(fs::exists(dir + "/plots/total_time_control_lateral.png"));
  // a malformed table is a file:line error
  write_file_atomic(dir + "/results.csv", csv + "9,A,1\n");
  const auto bad = testing::run_paddock("sweep report " + dir);
  EXPECT_EQ(bad.code, 2);
  EXPECT_THAT(bad.output, HasSubstr("results.csv:10: expected 28 cells, got 3"));
}

}  // namespace
}  // namespace paddock::runner
