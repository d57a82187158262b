#pragma once
// what a run leaves behind: the readable summary, summary.json, log.csv, and
// the check of a scenario's [expect] section.
#include <optional>
#include <string>
#include <vector>

#include "sim/runner/scenario.h"
#include "sim/runner/simulation.h"

namespace paddock::runner {

// each [expect] entry that does not hold, as "what: expected ..., got ..."
std::vector<std::string> check_expectations(const Expectations& e, const RunResult& r);

// the readable summary printed by `paddock run`
std::string summary_text(const Scenario& s, const RunResult& r, const std::vector<std::string>& failed);

// one JSON object (schema in the README)
std::string summary_json(const Scenario& s, const RunResult& r, const std::vector<std::string>& failed);

// a profile (profile.h) as a Markdown table, the largest stage first:
// seconds, share, milliseconds per simulated second (of sim_time s)
std::string profile_table(const Profile& p, double sim_time);
// `run --profile`: the run's wall time by stage as profile_table, then the
// loop's page faults, allocations and peak memory
std::string profile_text(const RunResult& r);

// the stack's last plan and map (plan.json): the map's optional layers
std::string plan_json(const RunResult& r);

// the perception snapshot (perception.json): scan time, labelled points
// [x, y, z, label], detected and true cones [x, y, colour tag] in the base
// frame, and the camera's boxes [x_min, y_min, x_max, y_max, colour tag] and
// projected cluster centres [u, v] (kept and dropped); the camera image goes
// to camera.png beside it
std::string perception_json(const PerceptionSnapshot& s);

// the log rows as CSV with a header line
inline constexpr const char* kLogHeader =
    "t,x,y,yaw,vx,vy,yaw_rate,steer_cmd,steer,throttle,brake,v_ref,lateral_error,heading_error,s,lap,as_state";
std::string log_csv(const std::vector<LogRow>& log);
// slam.csv: the estimate against the truth at every log sample (slam != ground_truth)
inline constexpr const char* kSlamCsvHeader = "t,x,y,yaw,x_true,y_true,yaw_true,error,sigma";
std::string slam_csv(const std::vector<SlamSample>& series);

// how the car answered an injected fault: the first thing the stack (a
// health event, AS Emergency) or the VCU (the EBS) did at or after it
struct FaultResponse {
  double t = 0.0;      // s
  double delay = 0.0;  // s after the fault
  std::string what;
};
std::optional<FaultResponse> fault_response(const RunResult& r, const FaultNote& f);

// the EBS's stop in words, against the rules' distance from its speed
std::string ebs_line(const EbsStop& e);

// a double as the shortest text that reads back to the same value
std::string fmt(double v);

}  // namespace paddock::runner
