#pragma once
// the FS dynamic events' rules: start, timing through gates, laps, penalties,
// finish, DNF. Fed by the simulator with ground truth; knows nothing of the stack
// beyond the AS state it reports.
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "autonomy/common/geometry.h"
#include "autonomy/common/params.h"
#include "sim/world/track.h"

namespace paddock::events {

enum class EventKind { Acceleration, Skidpad, Autocross, Trackdrive };

// the FS rules as encoded by PacSim, ARUSSim and FSSIM (ORACLES.md)
struct Rules {
  int laps = 10;                  // laps to drive (timed ones included)
  std::vector<int> timed_laps;    // 1-based laps whose times score; empty: all
  bool score_mean = false;        // the score is the mean of the timed laps (skidpad), not their sum
  double doo_penalty = 2.0;       // s per cone down or out
  double oc_penalty = 10.0;       // s per off-course excursion
  double uss_penalty = 10.0;      // s for an unsafe stop
  double stop_zone = 30.0;        // m from the finish crossing within which the car must come to rest
};
Rules rules_for(EventKind kind);

// the simulator's judgement calls that the rules leave open
struct EventParams {
  double timeout = 900.0;
  double stop_time = 30.0;
  double off_track_dnf_time = 5.0;
  double stall_time = 10.0;
  double standstill_speed = 0.05;
  double ready_timeout = 60.0;

  // the longest a run can go on (s): the go by ready_timeout, the timeout
  // after it, then the stop after the finish
  double longest_run() const { return ready_timeout + timeout + stop_time; }

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(timeout), {"s", params::in(1.0, 86400.0), "sim time after the go signal before a DNF"});
    v(PADDOCK_PARAM(stop_time), {"s", params::in(1.0, 600.0), "time after the finish within which the car must be at rest"});
    v(PADDOCK_PARAM(off_track_dnf_time), {"s", params::in(0.01, 600.0), "time with all four wheels off the track that ends the run (DNF)"});
    v(PADDOCK_PARAM(stall_time), {"s", params::in(0.1, 600.0), "time at rest on track before the finish that ends the run (DNF)"});
    v(PADDOCK_PARAM(standstill_speed), {"m/s", params::in(0.0, 5.0), "slower counts as at rest"});
    v(PADDOCK_PARAM(ready_timeout), {"s", params::in(1.0, 86400.0), "sim time without the go (the car never held AS Ready long enough) before a DNF"});
  }
};

struct Lap {
  int number = 0;        // 1-based
  double start = 0.0;    // sim time of the crossing that started it (s)
  double time = 0.0;     // lap time (s)
  bool timed = true;     // counts towards the score
  int doo = 0;           // cones down or out during this lap
  int oc = 0;            // off-course excursions that began during this lap
  double energy = 0.0;   // drawn from the accumulator during the lap, regeneration counted off (J)
};

struct Result {
  bool finished = false;       // crossed the finish, stopped in the zone, AS finished
  std::string dnf_reason;      // why not, when not
  std::vector<Lap> laps;       // completed laps
  int doo = 0;
  int oc = 0;
  int uss = 0;
  double raw_time = 0.0;       // sum (or mean, skidpad) of the timed laps (s)
  double total_time = 0.0;     // raw time plus penalties (s)
  double finish_time = 0.0;    // sim time of the end of the run (s)
};

// what the event sees of the car each time it is updated
struct CarSample {
  double t = 0.0;                  // sim time (s)
  Vec2 nose;                       // the timing point: the car's front (map frame)
  std::array<Vec2, 4> wheels;      // contact patches (map frame)
  double speed = 0.0;              // m/s
  bool as_finished = false;        // the car reports AS Finished
  bool as_emergency = false;       // the car reports AS Emergency
  int doo_total = 0;               // cones down or out so far (the world counts them)
  double energy = 0.0;             // drawn from the accumulator so far, regeneration counted off (J)
};

class Event {
 public:
  // throws std::invalid_argument when params::validate(params) fails
  Event(EventKind kind, const world::TrackModel& track, const EventParams& params);

  // timing: called every physics step with the nose's motion since the last call
  void on_motion(double t0, Vec2 nose0, double t1, Vec2 nose1);
  // penalties, the finish and DNF: called at the sample rate (100 Hz)
  void on_sample(const CarSample& s);
  // the go signal was given at this time
  void start(double t) { go_time_ = t; }
  // the run cannot go on (the simulation diverged): a DNF at t with this reason
  void abort(double t, const std::string& reason);

  bool done() const { return done_; }
  const Result& result() const { return result_; }
  int laps_completed() const { return static_cast<int>(result_.laps.size()); }
  // the lap being driven (1-based), 0 before the first crossing
  int current_lap() const { return lap_running_ ? laps_completed() + 1 : 0; }
  EventKind kind() const { return kind_; }
  const Rules& rules() const { return rules_; }

 private:
  void crossed(double t, std::size_t gate, Vec2 where);
  void finish_run(bool finished, const std::string& reason, double t);

  EventKind kind_;
  Rules rules_;
  EventParams params_;
  std::vector<Segment> gates_;      // the timing gates in use
  const world::TrackModel* track_;  // for the on-track test

  std::optional<double> go_time_;
  std::optional<double> emergency_since_;  // the car reported AS Emergency: the EBS brakes it to rest
  bool lap_running_ = false;
  double lap_start_ = 0.0;
  double energy_ = 0.0;             // the car's energy counter at the last sample (J)
  double energy_at_lap_start_ = 0.0;
  bool crossed_finish_ = false;     // all laps done: the car must now stop
  double finish_cross_time_ = 0.0;
  Vec2 finish_cross_point_;
  bool off_track_ = false;
  double off_track_since_ = 0.0;
  std::optional<double> at_rest_since_;
  int doo_at_lap_start_ = 0;
  int last_doo_total_ = 0;
  int oc_in_lap_ = 0;
  bool done_ = false;
  Result result_;
};

const char* to_string(EventKind k);

}  // namespace paddock::events
