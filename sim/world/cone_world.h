#pragma once
// the cone world: a cone in play is a Box2D body that slides on the ground
// with Coulomb friction, the car is a kinematic body moved by the vehicle
// model, and the FS "down or out" (DOO) rule is decided from contact impulses
// and cone displacement. Cones at rest away from everything are grid entries,
// not bodies, and Box2D does not step while nothing can touch (see
// cone_world.cc). Box2D lives behind a pimpl: this header does not include it.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "autonomy/common/cone.h"
#include "autonomy/common/geometry.h"
#include "autonomy/common/params.h"

namespace paddock::world {

// one cone type. The sizes are the FS rule sizes (ORACLES.md "Cones and LiDAR").
struct ConeSpec {
  double base_width = 0.228;
  double height = 0.325;
  double mass = 0.9;
  double knock_impulse = 1.5;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(base_width), {"m", params::above(0.0), "side of the square base (the collision circle's diameter)"});
    v(PADDOCK_PARAM(height), {"m", params::above(0.0), "height"});
    v(PADDOCK_PARAM(mass), {"kg", params::in(0.01, 100.0), "mass"});
    v(PADDOCK_PARAM(knock_impulse), {"N s", params::above_up_to(0.0, 1000.0), "a contact impulse above this in one step knocks the cone over"});
  }
};

// the smallest horizontal impulse (N s), applied at hit_height (m) above the
// ground, that tips over a cone of the given base width (m), height (m) and
// mass (kg). Model: a uniform solid cone of base radius b = base_width/2
// (centre of mass at h/4, inertia about a horizontal axis through it
// m (3/20 b^2 + 3/80 h^2)) that pivots on its far base edge. The impulse J
// gives it the angular momentum J * hit_height about that edge; it falls when
// the kinetic energy (J hit_height)^2 / (2 I_edge) exceeds the work m g (rho -
// h/4) that lifts the centre of mass over the edge, rho = sqrt(b^2 + (h/4)^2):
//   J = sqrt(2 I_edge m g (rho - h/4)) / hit_height,  I_edge = I_cm + m rho^2.
double tipping_impulse(double base_width, double height, double mass, double hit_height);

struct ConeWorldParams {
  // small cone (blue, yellow, small orange, unknown): 228 x 228 x 325 mm; 0.9 kg
  // is the mass of a PVC traffic cone of that height with a weighted base (FS
  // small cones weigh about 0.9-1.0 kg). Knock impulse: tipping_impulse(0.228,
  // 0.325, 0.9, 0.10) = 1.54 N s, with the car meeting the cone 0.10 m above
  // the ground (front wing end plate / nose of an FS car); rounded to 1.5 N s,
  // i.e. a speed change of the cone of 1.7 m/s.
  ConeSpec small_cone{0.228, 0.325, 0.9, 1.5};
  // big orange cone: 285 x 285 x 505 mm, about 1.9 kg; tipping_impulse(0.285,
  // 0.505, 1.9, 0.10) = 4.71 N s, rounded to 4.7 N s (a speed change of 2.5 m/s).
  ConeSpec big_cone{0.285, 0.505, 1.9, 4.7};
  // rubber/PVC on dry asphalt is 0.5-0.8; a sliding cone decelerates at
  // ground_friction * g. Modelled by a b2FrictionJoint from each cone to the
  // ground (max force mu m g, max torque mu m g times the base's mean radius):
  // a constant deceleration and a definite stop after v^2 / (2 mu g). Linear
  // damping would decay the speed exponentially (stopping distance v / c,
  // never a stop).
  double ground_friction = 0.6;
  // contact between the car and a cone, and between two cones (same materials:
  // PVC cone on carbon/plastic bodywork or on another cone); impacts slower
  // than 1 m/s are inelastic (Box2D's restitution threshold).
  double car_cone_friction = 0.4;
  double car_cone_restitution = 0.2;
  int velocity_iterations = 8;
  int position_iterations = 3;

  // performance: skip b2World::Step while no cone is awake and no cone is
  // within wake_margin of the car footprint, and keep only the cones within
  // world_margin of the car or of a moving cone as Box2D bodies (the outcome
  // is the same up to float rounding; false = plain Box2D: every cone a body,
  // a Box2D step every time, for tests and comparisons).
  bool skip_idle_steps = true;
  // the clearance bound is exact (it follows every footprint point), so this
  // only has to cover float rounding: 2 cm
  double wake_margin = 0.02;
  double world_margin = 0.30;
  double query_reach = 2.0;
  // a cone slower than rest_speed and rest_spin with no touching contact for
  // rest_time is put to sleep (Box2D alone waits 0.5 s)
  double rest_speed = 0.01;
  double rest_spin = 0.035;
  double rest_time = 0.02;

  template <class V>
  void visit(V& v) {
    v.section(PADDOCK_PARAM(small_cone), "the small cone (blue, yellow, small orange, unknown)");
    v.section(PADDOCK_PARAM(big_cone), "the big orange cone");
    v(PADDOCK_PARAM(ground_friction), {"", params::in(0.0, 5.0), "Coulomb friction coefficient of a cone base on asphalt"});
    v(PADDOCK_PARAM(car_cone_friction), {"", params::in(0.0, 5.0), "car-cone (and cone-cone) friction coefficient"});
    v(PADDOCK_PARAM(car_cone_restitution), {"", params::fraction(), "car-cone (and cone-cone) restitution"});
    v(PADDOCK_PARAM(velocity_iterations), {"", params::at_least(1), "Box2D velocity iterations per step"});
    v(PADDOCK_PARAM(position_iterations), {"", params::at_least(1), "Box2D position iterations per step"});
    v(PADDOCK_PARAM(skip_idle_steps), "skip Box2D steps while nothing can touch and keep only nearby cones as bodies (false: plain Box2D)");
    v(PADDOCK_PARAM(wake_margin), {"m", params::above(0.0), "car-to-cone-edge clearance below which Box2D steps"});
    v(PADDOCK_PARAM(world_margin), {"m", params::above(0.0), "clearance to the car or a moving cone within which a cone is a Box2D body"});
    v(PADDOCK_PARAM(query_reach), {"m", params::above(0.0), "how far around the car one proximity query looks"});
    v(PADDOCK_PARAM(rest_speed), {"m/s", params::at_least(0.0), "a cone slower than this (and rest_spin) may go to sleep"});
    v(PADDOCK_PARAM(rest_spin), {"rad/s", params::at_least(0.0), "a cone spinning slower than this (and rest_speed) may go to sleep"});
    v(PADDOCK_PARAM(rest_time), {"s", params::at_least(0.0), "time at rest without a touching contact before a cone sleeps"});
  }
  std::string check() const {
    if (!(world_margin >= wake_margin)) return "world_margin must be >= wake_margin";
    if (!(query_reach > wake_margin)) return "query_reach must be > wake_margin";
    return "";
  }
};

// the car's outline in its base frame (origin at the rear axle centre, x
// forward, y left): x from -rear to +front, y from -half_width to +half_width (m)
struct Footprint {
  double rear = 0.0;
  double front = 0.0;
  double half_width = 0.0;
};

enum class DooCause { Knocked, Displaced };

struct DooEvent {
  int cone = -1;              // index in the constructor's cone list
  std::int64_t step = 0;      // 1-based number of the accepted step() during which it happened
  std::int64_t time_ns = 0;   // sim time at the end of that step, counted from construction
  DooCause cause = DooCause::Knocked;
};

struct ConeWorldStats {
  std::int64_t steps = 0;             // accepted step() calls
  std::int64_t box2d_steps = 0;       // of which ran b2World::Step
  std::int64_t proximity_queries = 0; // car-to-cone clearance queries on the grid
  std::int64_t rejected_steps = 0;    // step() calls ignored (non-finite input or dt <= 0)
  std::int64_t bodies_created = 0;    // cone bodies put into the Box2D world
};

class ConeWorld {
 public:
  // throws std::invalid_argument when params::validate(params) fails or the footprint is
  // degenerate (front + rear and half_width must exceed 5 cm) or a cone
  // position is not finite. Every cone starts asleep at its given position.
  ConeWorld(std::vector<Cone> cones, const ConeWorldParams& params, const Footprint& footprint);
  ~ConeWorld();
  ConeWorld(ConeWorld&&) noexcept;
  ConeWorld& operator=(ConeWorld&&) noexcept;
  ConeWorld(const ConeWorld&) = delete;
  ConeWorld& operator=(const ConeWorld&) = delete;

  // advance by dt (s); car_pose is the car's base pose (map frame) at the END
  // of the step. The kinematic car body is placed at the previous pose and
  // given the velocity that carries it to car_pose in exactly dt, so contacts
  // see the true relative velocity. The passed velocities (m/s, rad/s) place
  // the car on the first step (previous pose = car_pose - v dt). A step with a
  // non-finite input or dt <= 0 is ignored and counted in stats().
  void step(const Pose2& car_pose, double car_vx_world, double car_vy_world, double yaw_rate, double dt);

  // give cone i a velocity (m/s, map frame), e.g. to script a disturbance; it
  // is not a contact, so it can only make the cone DOO by displacement.
  // Throws std::out_of_range for a bad index; a non-finite velocity is ignored.
  void kick_cone(int i, Vec2 velocity);

  // an outside force (the wind) moves cone i: it slides `shift` (m, map frame)
  // on the ground's friction (it is given the speed sqrt(2 mu g |shift|)
  // along it; with no friction it keeps |shift| per second) and, if
  // `topple`, lies on its side from now on (cone_knocked). What it does until
  // it rests again is not the car's: neither its own DOO nor that of a cone it
  // pushes is counted (the cones it touches share the outside cause). Once at
  // rest it stands in a new place: a cone is out when moved more than its base
  // radius from there, and a toppled cone the car hits counts as knocked.
  // Throws std::out_of_range for a bad index; a non-finite shift is ignored.
  void disturb_cone(int i, Vec2 shift, bool topple);

  int cone_count() const;
  const Cone& cone(int i) const;     // as given to the constructor
  Vec2 cone_position(int i) const;   // current position (m); bit-identical to the input while untouched
  bool cone_knocked(int i) const;    // lying: ever hit by an impulse above its knock threshold, or toppled
  bool cone_doo(int i) const;
  int doo_count() const;
  std::vector<int> doo_cones() const;           // cone indices, in the order they became DOO
  const std::vector<DooEvent>& doo_events() const;
  std::int64_t doo_step(int i) const;           // -1 while cone i is not DOO
  std::int64_t doo_time_ns(int i) const;        // -1 while cone i is not DOO

  int bodies_in_world() const;    // cones that are Box2D bodies now
  Pose2 car_pose() const;         // the last accepted car pose
  std::int64_t time_ns() const;   // sum of the accepted dt, rounded to ns each
  const ConeWorldStats& stats() const;
  const ConeWorldParams& params() const;
  const Footprint& footprint() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace paddock::world
