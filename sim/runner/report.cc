#include "sim/runner/report.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include <nlohmann/json.hpp>

#include "autonomy/common/format.h"
#include "sim/world/track.h"

namespace paddock::runner {

std::string fmt(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

std::vector<std::string> check_expectations(const Expectations& e, const RunResult& r) {
  std::vector<std::string> failed;
  const auto& ev = r.event;
  const int laps = static_cast<int>(ev.laps.size());
  if (e.finished && *e.finished != ev.finished) {
    failed.push_back(std::string("finished: expected ") + (*e.finished ? "true" : "false") + ", got " +
                     (ev.finished ? "true" : "false (" + ev.dnf_reason + ")"));
  }
  if (e.laps && laps != *e.laps) failed.push_back("laps: expected " + std::to_string(*e.laps) + ", got " + std::to_string(laps));
  if (e.doo_max && ev.doo > *e.doo_max) failed.push_back("doo: expected at most " + std::to_string(*e.doo_max) + ", got " + std::to_string(ev.doo));
  if (e.oc_max && ev.oc > *e.oc_max) failed.push_back("oc: expected at most " + std::to_string(*e.oc_max) + ", got " + std::to_string(ev.oc));
  if (e.uss_max && ev.uss > *e.uss_max) failed.push_back("uss: expected at most " + std::to_string(*e.uss_max) + ", got " + std::to_string(ev.uss));
  for (const auto& lap : ev.laps) {
    if (e.lap_time_max && lap.time > *e.lap_time_max) {
      failed.push_back("lap " + std::to_string(lap.number) + " time: expected at most " + fixed(*e.lap_time_max, 3) + " s, got " + fixed(lap.time, 3) + " s");
    }
    if (e.lap_time_min && lap.time < *e.lap_time_min) {
      failed.push_back("lap " + std::to_string(lap.number) + " time: expected at least " + fixed(*e.lap_time_min, 3) + " s, got " + fixed(lap.time, 3) + " s");
    }
  }
  if (e.total_time_max && ev.total_time > *e.total_time_max) {
    failed.push_back("total time: expected at most " + fixed(*e.total_time_max, 3) + " s, got " + fixed(ev.total_time, 3) + " s");
  }
  if (!r.stack_remote && e.lateral_rms_max && r.tracking.rms > *e.lateral_rms_max) {
    failed.push_back("lateral rms: expected at most " + fixed(*e.lateral_rms_max, 3) + " m, got " + fixed(r.tracking.rms, 3) + " m");
  }
  if (!r.stack_remote && e.lateral_error_max && r.tracking.max > *e.lateral_error_max) {
    failed.push_back("lateral max: expected at most " + fixed(*e.lateral_error_max, 3) + " m, got " + fixed(r.tracking.max, 3) + " m");
  }
  if (!r.stack_remote && e.ate_rms_max && r.slam.ate_rms > *e.ate_rms_max) {
    failed.push_back("ATE rms: expected at most " + fixed(*e.ate_rms_max, 3) + " m, got " + fixed(r.slam.ate_rms, 3) + " m");
  }
  if (!r.stack_remote && e.ate_max_max && r.slam.ate_max > *e.ate_max_max) {
    failed.push_back("ATE max: expected at most " + fixed(*e.ate_max_max, 3) + " m, got " + fixed(r.slam.ate_max, 3) + " m");
  }
  if (!r.stack_remote && e.map_recall_min && r.slam.map.recall < *e.map_recall_min) {
    failed.push_back("map recall: expected at least " + fixed(*e.map_recall_min, 3) + ", got " + fixed(r.slam.map.recall, 3));
  }
  if (e.best_above_limit_max) {
    double best = std::numeric_limits<double>::infinity();
    for (const auto& lap : ev.laps) best = std::min(best, lap.time);
    if (!r.limit_lap) {
      failed.push_back("best lap above the limit: the track has no limit lap (not a circuit)");
    } else if (!(best / *r.limit_lap - 1.0 <= *e.best_above_limit_max)) {
      failed.push_back("best lap above the limit: expected at most " + fixed(100.0 * *e.best_above_limit_max, 1) + " %, got " +
                       (ev.laps.empty() ? std::string("no lap") : fixed(100.0 * (best / *r.limit_lap - 1.0), 1) + " %"));
    }
  }
  // the car's own report (the last log row's AS state), the VCU's for a stack in the car binary
  const bool emergency = (!r.log.empty() && r.log.back().as_state == static_cast<int>(hal::AsState::Emergency)) ||
                         (r.ebs.fired && r.ebs.cause.find("AS Emergency") != std::string::npos);
  if (e.emergency && *e.emergency != emergency) {
    failed.push_back(std::string("emergency: expected ") + (*e.emergency ? "AS Emergency" : "no AS Emergency") + ", got " +
                     (emergency ? "AS Emergency" : "none") + (r.ebs.fired ? " (EBS: " + r.ebs.cause + ")" : ""));
  }
  if (e.ebs_within_rules) {
    const bool within = r.ebs.fired && r.ebs.stopped_at && r.ebs.distance <= ebs_rules_distance(r.ebs.speed);
    if (*e.ebs_within_rules != within) {
      failed.push_back(std::string("EBS within the rules: expected ") + (*e.ebs_within_rules ? "yes" : "no") + ", got " +
                       (r.ebs.fired ? ebs_line(r.ebs) : std::string("the EBS never fired")));
    }
  }
  if (e.notice_max) {
    for (const FaultNote& f : r.faults) {
      const std::optional<FaultResponse> n = fault_response(r, f);
      if (!n) {
        failed.push_back("notice: " + f.name + " at " + fixed(f.at, 3) + " s was never noticed");
      } else if (n->delay > *e.notice_max) {
        failed.push_back("notice: " + f.name + ": expected within " + fixed(*e.notice_max, 3) + " s, got " + fixed(n->delay, 3) + " s");
      }
    }
  }
  if (e.doo_after_fault_max && !r.faults.empty()) {
    int after = 0;
    for (const ConeHit& h : r.cones_hit) after += h.t >= r.faults.front().at ? 1 : 0;
    if (after > *e.doo_after_fault_max)
      failed.push_back("doo after the fault: expected at most " + std::to_string(*e.doo_after_fault_max) + ", got " + std::to_string(after));
  }
  if (!r.stack_remote && e.fallbacks_max && r.fallbacks > *e.fallbacks_max) {
    failed.push_back("fallbacks: expected at most " + std::to_string(*e.fallbacks_max) + ", got " + std::to_string(r.fallbacks));
  }
  if (r.stack_remote) {
    // what only the stack knows stayed in the car binary's process
    const std::pair<bool, const char*> inside[] = {{e.lateral_rms_max.has_value(), "lateral rms"},
                                                   {e.lateral_error_max.has_value(), "lateral max"},
                                                   {e.ate_rms_max.has_value(), "ATE rms"},
                                                   {e.ate_max_max.has_value(), "ATE max"},
                                                   {e.map_recall_min.has_value(), "map recall"},
                                                   {e.fallbacks_max.has_value(), "fallbacks"}};
    for (const auto& [set, what] : inside)
      if (set) failed.push_back(std::string(what) + ": not measured: the stack ran in the car binary (transport = udp)");
  }
  return failed;
}

std::optional<FaultResponse> fault_response(const RunResult& r, const FaultNote& f) {
  std::optional<FaultResponse> best;
  const auto consider = [&](double t, const std::string& what) {
    if (t + 1e-9 >= f.at && (!best || t < best->t)) best = FaultResponse{t, t - f.at, what};
  };
  for (const stack::HealthEvent& e : r.health) consider(to_seconds(e.t), "the stack: " + e.what);
  for (const stack::AsTransition& a : r.as_transitions)
    if (a.to == hal::AsState::Emergency) consider(to_seconds(a.t), std::string("the stack: AS Emergency (") + a.reason + ")");
  if (r.ebs.fired) consider(r.ebs.t, "the VCU: EBS fired (" + r.ebs.cause + ")");
  return best;
}

std::string ebs_line(const EbsStop& e) {
  std::string l = "fired at " + fixed(e.t, 3) + " s (" + e.cause + ") at " + fixed(e.speed, 2) + " m/s: ";
  if (!e.stopped_at) return l + "still rolling when the run ended, after " + fixed(e.distance, 2) + " m";
  const double allowed = ebs_rules_distance(e.speed);
  return l + "at rest after " + fixed(e.distance, 2) + " m and " + fixed(*e.stopped_at - e.t, 2) + " s (mean " +
         fixed(e.mean_decel(), 1) + " m/s^2); the rules allow " + fixed(allowed, 2) +
         " m from that speed (T 15.3 / IN 6.3: 0.2 s, then 8 m/s^2): " + (e.distance <= allowed ? "within" : "EXCEEDED");
}

std::string summary_text(const Scenario& s, const RunResult& r, const std::vector<std::string>& failed) {
  std::ostringstream o;
  const auto& ev = r.event;
  const events::Rules rules = events::rules_for(s.scenario.event);
  o << s.name << ": " << events::to_string(s.scenario.event) << " on " << s.track_path << "\n";
  o << "  result      " << (ev.finished ? "finished" : "DNF: " + ev.dnf_reason) << "\n";
  o << "  lap     time [s]   DOO  OC   rms [m]  max [m]  ITAE   energy [Wh]" << (r.limit_lap ? "  above limit" : "") << "\n";
  for (std::size_t i = 0; i < ev.laps.size(); ++i) {
    const auto& lap = ev.laps[i];
    const auto& tr = r.lap_tracking[i];
    char buf[200];
    if (r.stack_remote) {  // the tracking errors are the car binary's
      std::snprintf(buf, sizeof buf, "  %3d%s %9.3f   %3d %3d   %7s  %7s  %7s  %8.1f", lap.number, lap.timed ? " " : "*",
                    lap.time, lap.doo, lap.oc, "-", "-", "-", lap.energy / 3600.0);
    } else {
      std::snprintf(buf, sizeof buf, "  %3d%s %9.3f   %3d %3d   %7.3f  %7.3f  %7.1f  %8.1f", lap.number,
                    lap.timed ? " " : "*", lap.time, lap.doo, lap.oc, tr.rms, tr.max, tr.itae, lap.energy / 3600.0);
    }
    o << buf;
    if (r.limit_lap) {
      std::snprintf(buf, sizeof buf, "  %+10.1f %%", 100.0 * (lap.time / *r.limit_lap - 1.0));
      o << buf;
    }
    o << "\n";
  }
  if (r.limit_lap) {
    o << "  limit       " << fixed(*r.limit_lap, 3)
      << " s: the car's QSS flying lap on the minimum-curvature line 1 m from the boundaries (paddock report limit)\n";
  }
  if (!rules.timed_laps.empty()) o << "  (* untimed lap)\n";
  o << "  penalties   DOO " << ev.doo << " x " << fixed(rules.doo_penalty, 1) << " s, OC " << ev.oc << " x "
    << fixed(rules.oc_penalty, 1) << " s, USS " << ev.uss << " x " << fixed(rules.uss_penalty, 1) << " s\n";
  for (const ConeHit& c : r.cones_hit) {
    o << "  cone down   " << cone_tag(c.color) << " at (" << fixed(c.position.x, 2) << ", " << fixed(c.position.y, 2)
      << ") " << (c.knocked ? "knocked over" : "pushed out of place") << " at t = " << fixed(c.t, 2) << " s\n";
  }
  o << "  time        raw " << fixed(ev.raw_time, 3) << " s" << (rules.score_mean ? " (mean of timed laps)" : "")
    << ", total " << fixed(ev.total_time, 3) << " s\n";
  if (r.stack_remote) {
    o << "  stack       in the car binary (transport = udp): its tracking, estimate, map and faults are its\n"
      << "              own (paddock car prints them)\n";
  } else {
    o << "  tracking    rms " << fixed(r.tracking.rms, 3) << " m, max " << fixed(r.tracking.max, 3) << " m, ITAE "
      << fixed(r.tracking.itae, 1) << " (mean per lap)\n";
    o << "  slam        " << stack::to_string(s.autonomy.slam) << ": ATE rms " << fixed(r.slam.ate_rms, 3) << " m, max "
      << fixed(r.slam.ate_max, 3) << " m, heading rms " << fixed(r.slam.heading_rms, 4) << " rad\n";
    if (r.slam.drift.windows > 0) {
      o << "              drift over 100 m: " << fixed(r.slam.drift.translation, 3) << " m, "
        << fixed(r.slam.drift.rotation, 4) << " rad (mean of " << r.slam.drift.windows << " windows)\n";
    }
    const MapMetrics& mm = r.slam.map;
    o << "              map " << mm.map_cones << " cones: rmse " << fixed(mm.rmse, 3) << " m, precision "
      << fixed(100.0 * mm.precision, 1) << " %, recall " << fixed(100.0 * mm.recall, 1) << " % (of " << mm.true_cones
      << " within 5 m of the path), colour " << fixed(100.0 * mm.colour_accuracy, 1) << " %\n";
    if (s.autonomy.slam != stack::SlamMode::GroundTruth) {
      o << "              " << r.slam.frames << " frames, " << r.slam.fallbacks << " unusable, " << r.slam.lost_frames
        << " lost, " << r.slam.relocalisations << " relocalisations, " << r.slam.rejected_messages
        << " refused odometry messages, " << r.slam.slide_samples << " slide samples, " << r.slam.loop_closures
        << " loop closures; update "
        << fixed(r.slam.update_ms_mean, 2) << " ms mean, " << fixed(r.slam.update_ms_p99, 2) << " ms p99\n";
    }
    if (s.autonomy.slam == stack::SlamMode::Lio || s.autonomy.slam == stack::SlamMode::LioGraph) {
      o << "              lio: " << r.slam.lio_slices << " slices, " << r.slam.lio_degenerate_slices
        << " with a pose direction unobserved, " << r.slam.lio_too_few_points << " with too few planes\n";
    }
  }
  o << "  energy      " << fixed(r.energy / 3600.0, 1) << " Wh drawn from the accumulator over the run (regeneration counted off)\n";
  if (r.perception.frames() > 0) {
    o << "  perception  " << stack::to_string(s.autonomy.perception) << ", " << r.perception.frames()
      << " frames against the truth (recall over the cones the sensor "
      << (s.autonomy.perception == stack::PerceptionMode::GroundTruth ? "had in view, unoccluded" : "hit with a point")
      << ")\n";
    o << "    range [m]  precision  recall  colour  error mean/max [m]  detections\n";
    std::vector<RangeBinStats> rows = r.perception.bins();
    rows.push_back(r.perception.total());
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const RangeBinStats& b = rows[i];
      if (b.detections == 0 && b.visible == 0) continue;
      const std::string range = i + 1 == rows.size() ? "all" : std::isinf(b.range_max) ? fixed(b.range_min, 0) + "+"
                                                     : fixed(b.range_min, 0) + "-" + fixed(b.range_max, 0);
      auto pct = [](double v) { return std::isnan(v) ? std::string("   -") : fixed(100.0 * v, 1) + "%"; };
      auto len = [](double v) { return std::isnan(v) ? std::string("-") : fixed(v, 3); };
      char buf[200];
      std::snprintf(buf, sizeof buf, "    %-9s  %9s  %6s  %6s  %8s / %-7s  %ld\n", range.c_str(), pct(b.precision()).c_str(),
                    pct(b.recall()).c_str(), pct(b.colour_accuracy()).c_str(), len(b.error_mean()).c_str(),
                    len(b.error_count > 0 ? b.error_max : std::nan("")).c_str(), b.detections);
      o << buf;
    }
  }
  if (!r.stack_remote)
    o << "  stack       " << r.fallbacks << " fallback cycles" << (r.fault.empty() ? "" : ", last fault: " + r.fault) << "\n";
  for (std::size_t i = 0; i < r.faults.size(); ++i) {
    const FaultNote& f = r.faults[i];
    o << (i == 0 ? "  faults      " : "              ") << f.name << " at " << fixed(f.at, 3) << " s: " << f.what << "\n";
    const std::optional<FaultResponse> n = fault_response(r, f);
    o << "                " << (n ? "noticed after " + fixed(n->delay, 3) + " s by " + n->what : std::string("not noticed")) << "\n";
  }
  for (std::size_t i = 0; i < r.health.size(); ++i) {
    o << (i == 0 ? "  health      " : "              ") << fixed(to_seconds(r.health[i].t), 3) << " s: " << r.health[i].what << "\n";
  }
  for (std::size_t i = 0; i < r.as_transitions.size(); ++i) {
    const stack::AsTransition& a = r.as_transitions[i];
    o << (i == 0 ? "  AS          " : "              ") << hal::to_string(a.from) << " -> " << hal::to_string(a.to)
      << " at " << fixed(to_seconds(a.t), 3) << " s: " << a.reason << "\n";
  }
  if (r.ebs.fired) o << "  EBS         " << ebs_line(r.ebs) << "\n";
  o << "  speed       " << fixed(r.sim_time, 1) << " s simulated in " << fixed(r.wall_time, 3) << " s ("
    << fixed(r.wall_time > 0 ? r.sim_time / r.wall_time : 0.0, 0) << "x real time)\n";
  if (!failed.empty()) {
    o << "  EXPECTATIONS FAILED:\n";
    for (const auto& f : failed) o << "    " << f << "\n";
  }
  return o.str();
}

namespace {
nlohmann::json slam_json(const Scenario& s, const SlamMetrics& m) {
  nlohmann::json laps = nlohmann::json::array();
  for (const SlamLap& l : m.laps) laps.push_back({{"ate_rms_m", l.ate_rms}, {"ate_max_m", l.ate_max}});
  return {{"mode", stack::to_string(s.autonomy.slam)},
          {"ate_rms_m", m.ate_rms},
          {"ate_max_m", m.ate_max},
          {"heading_rms_rad", m.heading_rms},
          {"drift_m_per_100m", m.drift.translation},
          {"drift_rad_per_100m", m.drift.rotation},
          {"samples", m.samples},
          {"map_cones", m.map.map_cones},
          {"map_rmse_m", m.map.rmse},
          {"map_precision", m.map.precision},
          {"map_recall", m.map.recall},
          {"map_colour_accuracy", m.map.colour_accuracy},
          {"loop_closures", m.loop_closures},
          {"frames", m.frames},
          {"fallbacks", m.fallbacks},
          {"lost_frames", m.lost_frames},
          {"relocalisations", m.relocalisations},
          {"rejected_messages", m.rejected_messages},
          {"slide_samples", m.slide_samples},
          {"update_ms_mean", m.update_ms_mean},
          {"update_ms_p99", m.update_ms_p99},
          {"lio_slices", m.lio_slices},
          {"lio_degenerate_slices", m.lio_degenerate_slices},
          {"lio_too_few_points", m.lio_too_few_points},
          {"laps", laps}};
}
}  // namespace

std::string profile_table(const Profile& p, double sim_time) {
  // the stages by their share, largest first; per simulated second the
  // wall milliseconds each costs (its share of the real-time factor) and,
  // where counted, the allocations it makes
  std::vector<Stage> order;
  for (std::size_t i = 0; i < kStageCount; ++i) order.push_back(static_cast<Stage>(i));
  std::stable_sort(order.begin(), order.end(), [&p](Stage a, Stage b) { return p.seconds(a) > p.seconds(b); });
  const double total = p.total();
  const bool counted = p.counts_allocations();
  const auto per_s = [sim_time](double x) { return sim_time > 0 ? x / sim_time : 0.0; };
  std::ostringstream o;
  o << "| stage | wall s | share | ms per simulated s |" << (counted ? " allocations per simulated s |" : "")
    << "\n|---|---:|---:|---:|" << (counted ? "---:|" : "") << "\n";
  for (Stage st : order) {
    const double sec = p.seconds(st);
    o << "| " << stage_name(st) << " | " << fixed(sec, 3) << " | " << fixed(total > 0 ? 100.0 * sec / total : 0.0, 1)
      << " % | " << fixed(1000.0 * per_s(sec), 2) << " |";
    if (counted) o << " " << fixed(per_s(static_cast<double>(p.allocations(st))), 0) << " |";
    o << "\n";
  }
  o << "| total | " << fixed(total, 3) << " | 100.0 % | " << fixed(1000.0 * per_s(total), 2) << " |";
  if (counted) o << " " << fixed(per_s(static_cast<double>(p.total_allocations())), 0) << " |";
  o << "\n";
  return o.str();
}

std::string profile_text(const RunResult& r) {
  std::ostringstream o;
  o << profile_table(r.profile, r.sim_time);
  const bool counted = r.profile.counts_allocations();
  const auto per_s = [&r](double x) { return r.sim_time > 0 ? x / r.sim_time : 0.0; };
  o << "page faults " << r.page_faults << " in the loop (" << fixed(per_s(static_cast<double>(r.page_faults)), 0)
    << " per simulated s)";
  if (counted) o << ", allocations " << r.profile.total_allocations();
  o << ", peak memory " << fixed(r.peak_rss_mb, 0) << " MiB\n";
  return o.str();
}

std::string summary_json(const Scenario& s, const RunResult& r, const std::vector<std::string>& failed) {
  using Json = nlohmann::ordered_json;
  const auto& ev = r.event;
  const events::Rules rules = events::rules_for(s.scenario.event);
  auto tracking = [](double rms, double max, double itae) { return Json{{"rms", rms}, {"max", max}, {"itae", itae}}; };
  Json laps = Json::array();
  for (std::size_t i = 0; i < ev.laps.size(); ++i) {
    const auto& lap = ev.laps[i];
    const auto& tr = r.lap_tracking[i];
    laps.push_back({{"lap", lap.number}, {"start", lap.start}, {"time", lap.time}, {"timed", lap.timed},
                    {"doo", lap.doo}, {"oc", lap.oc}, {"tracking", r.stack_remote ? Json(nullptr) : tracking(tr.rms, tr.max, tr.itae)},
                    {"energy", lap.energy},
                    {"above_limit", r.limit_lap ? Json(lap.time / *r.limit_lap - 1.0) : Json(nullptr)}});
  }
  Json cones = Json::array();
  for (const ConeHit& c : r.cones_hit) {
    cones.push_back({{"x", c.position.x}, {"y", c.position.y}, {"color", std::string(cone_tag(c.color))},
                     {"t", c.t}, {"cause", c.knocked ? "knocked" : "displaced"}});
  }
  Json bins = Json::array();
  auto bin_json = [](const RangeBinStats& b) {
    // NaN (nothing to count) is written as null
    return Json{{"range_min", b.range_min},
                {"range_max", std::isinf(b.range_max) ? Json(nullptr) : Json(b.range_max)},
                {"precision", b.precision()},
                {"recall", b.recall()},
                {"colour_accuracy", b.colour_accuracy()},
                {"position_error_mean", b.error_mean()},
                {"position_error_max", b.error_count > 0 ? Json(b.error_max) : Json(nullptr)},
                {"detections", b.detections},
                {"detections_matched", b.detections_matched},
                {"visible", b.visible},
                {"visible_matched", b.visible_matched},
                {"colour_unknown", b.colour_unknown}};
  };
  for (const RangeBinStats& b : r.perception.bins()) bins.push_back(bin_json(b));
  const Json perception = {{"mode", stack::to_string(s.autonomy.perception)},
                           {"frames", r.perception.frames()},
                           {"bins", bins},
                           {"all", bin_json(r.perception.total())}};
  const double penalty_s = rules.doo_penalty * ev.doo + rules.oc_penalty * ev.oc + rules.uss_penalty * ev.uss;
  Json as_transitions = Json::array();
  for (const stack::AsTransition& a : r.as_transitions)
    as_transitions.push_back({{"t", to_seconds(a.t)}, {"from", hal::to_string(a.from)}, {"to", hal::to_string(a.to)}, {"reason", a.reason}});
  Json faults = Json::array();
  for (const FaultNote& f : r.faults) {
    const std::optional<FaultResponse> n = fault_response(r, f);
    faults.push_back({{"name", f.name},
                      {"what", f.what},
                      {"at", f.at},
                      {"noticed_after", n ? Json(n->delay) : Json(nullptr)},
                      {"response", n ? Json(n->what) : Json(nullptr)}});
  }
  Json health = Json::array();
  for (const stack::HealthEvent& h : r.health) health.push_back({{"t", to_seconds(h.t)}, {"what", h.what}});
  Json ebs = nullptr;
  if (r.ebs.fired) {
    ebs = {{"t", r.ebs.t},
           {"cause", r.ebs.cause},
           {"speed", r.ebs.speed},
           {"distance", r.ebs.distance},
           {"stop_time", r.ebs.stopped_at ? Json(*r.ebs.stopped_at - r.ebs.t) : Json(nullptr)},
           {"mean_decel", r.ebs.stopped_at ? Json(r.ebs.mean_decel()) : Json(nullptr)},
           {"rules_distance", ebs_rules_distance(r.ebs.speed)},
           {"within_rules", r.ebs.stopped_at.has_value() && r.ebs.distance <= ebs_rules_distance(r.ebs.speed)}};
  }
  // wall seconds per stage (profile.h), in the stages' order
  Json profile = Json::object();
  for (std::size_t i = 0; i < kStageCount; ++i) {
    const auto stage = static_cast<Stage>(i);
    profile[std::string(stage_name(stage))] = r.profile.seconds(stage);
  }
  // the loop's allocations, in all and per stage (null where not counted:
  // a sanitizer's build)
  Json allocations = nullptr;
  if (r.profile.counts_allocations()) {
    allocations = {{"total", r.profile.total_allocations()}};
    for (std::size_t i = 0; i < kStageCount; ++i) {
      const auto stage = static_cast<Stage>(i);
      allocations[std::string(stage_name(stage))] = r.profile.allocations(stage);
    }
  }
  // JSON has no NaN or infinity: nlohmann writes them as null
  const Json j = {
      {"scenario", s.name},
      {"track", s.track_path},
      {"event", events::to_string(s.scenario.event)},
      {"seed", s.scenario.seed},
      {"finished", ev.finished},
      {"dnf_reason", ev.dnf_reason},
      {"limit_lap_s", r.limit_lap ? Json(*r.limit_lap) : Json(nullptr)},
      {"laps", laps},
      {"penalties", {{"doo", ev.doo}, {"oc", ev.oc}, {"uss", ev.uss}, {"seconds", penalty_s}, {"cones", cones}}},
      {"raw_time", ev.raw_time},
      {"total_time", ev.total_time},
      {"sim_time", r.sim_time},
      {"wall_time", r.wall_time},
      {"realtime_factor", r.wall_time > 0 ? r.sim_time / r.wall_time : 0.0},
      {"profile", profile},
      {"page_faults", r.page_faults},
      {"allocations", allocations},
      {"peak_rss_mb", r.peak_rss_mb},
      {"tracking", r.stack_remote ? Json(nullptr) : tracking(r.tracking.rms, r.tracking.max, r.tracking.itae)},
      {"energy", r.energy},
      {"slam", r.stack_remote ? Json(nullptr) : Json(slam_json(s, r.slam))},
      {"perception", r.stack_remote ? Json(nullptr) : perception},
      {"stack", r.stack_remote ? Json("car binary") : Json{{"fallbacks", r.fallbacks}, {"fault", r.fault}}},
      {"as_transitions", as_transitions},
      {"faults", faults},
      {"health", health},
      {"ebs", ebs},
      {"expectations_failed", failed},
  };
  return j.dump() + "\n";
}

std::string plan_json(const RunResult& r) {
  using Json = nlohmann::ordered_json;
  auto points = [](const std::vector<Vec2>& pts) {
    Json a = Json::array();
    for (const Vec2& p : pts) a.push_back({p.x, p.y});
    return a;
  };
  Json edges = Json::array();
  for (const Segment& s : r.plan.triangulation) edges.push_back({s.a.x, s.a.y, s.b.x, s.b.y});
  Json cones = Json::array();
  Json gates = Json::array();
  for (const Segment& g : r.plan.gates) gates.push_back({g.a.x, g.a.y, g.b.x, g.b.y});
  for (const Cone& c : r.plan.mapped_cones) cones.push_back({c.position.x, c.position.y, std::string(cone_tag(c.color))});
  const Json j = {{"triangulation", edges},
                  {"midpoints", points(r.plan.midpoints)},
                  {"centreline", points(r.plan.centreline)},
                  {"mapped_cones", cones},
                  {"gates", gates},
                  {"reference", points(r.plan.reference)}};
  return j.dump() + "\n";
}

std::string perception_json(const PerceptionSnapshot& s) {
  using Json = nlohmann::ordered_json;
  Json points = Json::array();
  for (const PerceptionSnapshot::Point& p : s.points) points.push_back({p.x, p.y, p.z, p.label});
  auto cones = [](const std::vector<Cone>& cs) {
    Json a = Json::array();
    for (const Cone& c : cs) a.push_back({c.position.x, c.position.y, std::string(cone_tag(c.color))});
    return a;
  };
  auto pixels = [](const std::vector<Vec2>& ps) {
    Json a = Json::array();
    for (const Vec2& p : ps) a.push_back({p.x, p.y});
    return a;
  };
  Json boxes = Json::array();
  for (const PerceptionSnapshot::Box& b : s.boxes)
    boxes.push_back({b.x_min, b.y_min, b.x_max, b.y_max, std::string(cone_tag(b.color))});
  Json j = {{"t", s.t}, {"points", points}, {"detected", cones(s.detected)}, {"truth", cones(s.truth)}};
  if (s.camera) {
    j["camera"] = {{"width", s.width}, {"height", s.height}, {"image", "camera.png"}, {"boxes", boxes},
                   {"projected", pixels(s.projected)}, {"dropped", pixels(s.dropped)}};
  }
  return j.dump() + "\n";
}

std::string log_csv(const std::vector<LogRow>& log) {
  std::string out = std::string(kLogHeader) + "\n";
  out.reserve(out.size() + log.size() * 200);
  for (const LogRow& r : log) {
    for (double v : {r.t, r.x, r.y, r.yaw, r.vx, r.vy, r.yaw_rate, r.steer_cmd, r.steer, r.throttle, r.brake, r.v_ref,
                     r.lateral_error, r.heading_error, r.s}) {
      out += fmt(v);
      out += ',';
    }
    out += std::to_string(r.lap);
    out += ',';
    out += std::to_string(r.as_state);
    out += '\n';
  }
  return out;
}

std::string slam_csv(const std::vector<SlamSample>& series) {
  std::string out = std::string(kSlamCsvHeader) + "\n";
  out.reserve(out.size() + series.size() * 120);
  for (const SlamSample& x : series) {
    const double v[] = {x.t, x.estimate.x, x.estimate.y, x.estimate.yaw, x.truth.x, x.truth.y, x.truth.yaw, x.error, x.sigma};
    for (std::size_t i = 0; i < std::size(v); ++i) {
      out += fmt(v[i]);
      out += i + 1 < std::size(v) ? ',' : '\n';
    }
  }
  return out;
}

}  // namespace paddock::runner
