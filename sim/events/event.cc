#include "sim/events/event.h"

#include <cmath>
#include <cstdio>

#include "autonomy/common/polyline.h"

namespace paddock::events {
namespace {

// "5 s", "0.25 s": a duration for messages
std::string seconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g s", s);
  return buf;
}

}  // namespace

const char* to_string(EventKind k) {
  switch (k) {
    case EventKind::Acceleration: return "acceleration";
    case EventKind::Skidpad: return "skidpad";
    case EventKind::Autocross: return "autocross";
    case EventKind::Trackdrive: return "trackdrive";
  }
  return "trackdrive";
}

Rules rules_for(EventKind kind) {
  Rules r;
  switch (kind) {
    case EventKind::Acceleration:
      r.laps = 1;  // one run from the start gate to the finish gate 75 m on
      r.stop_zone = 100.0;  // the braking zone after the finish gate
      break;
    case EventKind::Skidpad:
      // right (untimed), right (timed), left (untimed), left (timed); mean of the timed
      r.laps = 4;
      r.timed_laps = {2, 4};
      r.score_mean = true;
      r.doo_penalty = 0.2;
      break;
    case EventKind::Autocross:
      r.laps = 1;
      break;
    case EventKind::Trackdrive:
      r.laps = 10;
      break;
  }
  return r;
}

Event::Event(EventKind kind, const world::TrackModel& track, const EventParams& params)
    : kind_(kind), rules_(rules_for(kind)), params_(params::require_valid(params, "EventParams")), track_(&track) {
  // acceleration times from the start gate to the finish gate; every other
  // event times laps across one gate
  if (kind == EventKind::Acceleration && track.gates.size() >= 2) {
    gates_ = {track.gates[0], track.gates[1]};
  } else if (!track.gates.empty()) {
    gates_ = {track.gates[0]};
  }
}

void Event::on_motion(double t0, Vec2 nose0, double t1, Vec2 nose1) {
  if (done_ || !go_time_) return;
  for (std::size_t g = 0; g < gates_.size(); ++g) {
    // the crossing time is interpolated inside the step
    if (const auto f = crossing_right_to_left(nose0, nose1, gates_[g])) {
      crossed(t0 + *f * (t1 - t0), g, nose0 + (nose1 - nose0) * *f);
    }
  }
}

void Event::crossed(double t, std::size_t gate, Vec2 where) {
  const std::size_t start_gate = 0;
  const std::size_t finish_gate = gates_.size() - 1;
  if (crossed_finish_) return;
  if (lap_running_ && gate == finish_gate) {
    Lap lap;
    lap.number = laps_completed() + 1;
    lap.start = lap_start_;
    lap.time = t - lap_start_;
    lap.doo = last_doo_total_ - doo_at_lap_start_;
    lap.oc = oc_in_lap_;
    lap.energy = energy_ - energy_at_lap_start_;
    lap.timed = rules_.timed_laps.empty();
    for (int n : rules_.timed_laps) lap.timed = lap.timed || n == lap.number;
    result_.laps.push_back(lap);
    lap_running_ = false;
    doo_at_lap_start_ = last_doo_total_;
    oc_in_lap_ = 0;
    if (laps_completed() >= rules_.laps) {
      crossed_finish_ = true;
      finish_cross_time_ = t;
      finish_cross_point_ = where;
      return;
    }
  }
  if (!lap_running_ && gate == start_gate) {
    lap_running_ = true;
    lap_start_ = t;
    energy_at_lap_start_ = energy_;
  }
}

void Event::on_sample(const CarSample& s) {
  if (done_) return;
  last_doo_total_ = s.doo_total;
  result_.doo = s.doo_total;
  energy_ = s.energy;

  const bool at_rest = s.speed < params_.standstill_speed;
  if (s.as_emergency && !emergency_since_) emergency_since_ = s.t;
  if (emergency_since_) {
    // the EBS brakes the car to rest: the run ends there (a DNF), the cones
    // it hits on the way still count
    if (at_rest) return finish_run(false, "the car went to AS Emergency", s.t);
    if (s.t - *emergency_since_ > params_.stop_time) {
      return finish_run(false, "the car went to AS Emergency and was not at rest within " + seconds(params_.stop_time), s.t);
    }
  }
  if (!go_time_) {
    if (s.t > params_.ready_timeout) {
      return finish_run(false, "no go: the car did not hold AS Ready long enough within " + seconds(params_.ready_timeout), s.t);
    }
    return;
  }

  // off course: all four wheels outside the boundaries; one excursion counts once
  bool all_off = true;
  for (const Vec2& w : s.wheels) all_off = all_off && !track_->on_track(w);
  if (all_off && !off_track_) {
    off_track_ = true;
    off_track_since_ = s.t;
    ++result_.oc;
    ++oc_in_lap_;
  } else if (!all_off) {
    off_track_ = false;
  }

  if (off_track_ && s.t - off_track_since_ > params_.off_track_dnf_time) {
    return finish_run(false, "left the track for good (all wheels off for longer than " +
                                 seconds(params_.off_track_dnf_time) + ")", s.t);
  }
  if (!at_rest) at_rest_since_.reset();
  else if (!at_rest_since_) at_rest_since_ = s.t;

  if (emergency_since_) return;
  if (crossed_finish_) {
    // after the finish: at rest and AS Finished, inside the stop zone
    if (at_rest && s.as_finished) {
      const double d = distance(s.nose, finish_cross_point_);
      if (d > rules_.stop_zone || off_track_) result_.uss = 1;
      return finish_run(true, "", s.t);
    }
    if (s.t - finish_cross_time_ > params_.stop_time) {
      return finish_run(false, "did not come to a stop with AS Finished within " +
                                   seconds(params_.stop_time) + " of the finish", s.t);
    }
    return;
  }
  if (s.t - *go_time_ > params_.timeout) return finish_run(false, "timeout", s.t);
  if (at_rest && s.t - *at_rest_since_ > params_.stall_time && s.t - *go_time_ > params_.stall_time) {
    return finish_run(false, "stopped on track before the finish", s.t);
  }
}

void Event::abort(double t, const std::string& reason) {
  if (!done_) finish_run(false, reason, t);
}

void Event::finish_run(bool finished, const std::string& reason, double t) {
  done_ = true;
  result_.finished = finished;
  result_.dnf_reason = reason;
  result_.finish_time = t;
  // the score: the timed laps' sum (or mean) plus the penalties
  double sum = 0.0;
  int n = 0;
  for (const Lap& lap : result_.laps) {
    if (!lap.timed) continue;
    sum += lap.time;
    ++n;
  }
  result_.raw_time = rules_.score_mean && n > 0 ? sum / n : sum;
  result_.total_time = result_.raw_time + rules_.doo_penalty * result_.doo + rules_.oc_penalty * result_.oc +
                       rules_.uss_penalty * result_.uss;
}

}  // namespace paddock::events
