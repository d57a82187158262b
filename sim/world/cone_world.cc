#include "sim/world/cone_world.h"

#include <box2d/box2d.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

// How the world stays cheap (the closed loop steps it at 1 kHz and the whole
// simulator must run >= 500x real time):
// - a cone at rest is not a Box2D body at all: it is a position in a uniform
//   grid. b2World::Step walks every body and joint several times (clearing
//   flags, building islands, synchronising, TOI), so its cost grows with the
//   number of bodies, asleep or not; the world holds only the car and the
//   cones within world_margin of the car or of a moving cone.
// - b2World::Step is skipped entirely while no cone moves and no cone is
//   within wake_margin of the car. The car-to-cone clearance comes from the
//   grid and is re-queried only once the car may have used it up: the motion
//   of any footprint point since the query is bounded by |dp| + |dyaw| r_max.
// - the kinematic car is placed in Box2D only when Box2D steps.
// A cone taken out of the world is asleep, untouched and at rest, so putting it
// back (same float position and angle, zero velocity) continues the same motion.

namespace paddock::world {

namespace {

// side of one cell of the uniform grid of resting cones (m)
constexpr double kCellSize = 2.0;
// the grid never has more cells than this; a larger extent gets larger cells
constexpr double kMaxCells = 1.0e6;

// mean distance from the centre of a square of half side a to its points:
// a (sqrt(2) + asinh(1)) / 3 = 0.7652 a. A square base pressing evenly on the
// ground resists spinning with torque mu m g times this arm.
constexpr double kSquareMeanRadius = 0.76519572;

// distance from a point q (car base frame) to the footprint rectangle, 0 inside
double rect_distance(const Footprint& fp, Vec2 q) {
  const double dx = std::max({-fp.rear - q.x, 0.0, q.x - fp.front});
  const double dy = std::max(std::abs(q.y) - fp.half_width, 0.0);
  return std::sqrt(dx * dx + dy * dy);
}

struct Box {
  double x0, y0, x1, y1;
};

}  // namespace

double tipping_impulse(double base_width, double height, double mass, double hit_height) {
  // uniform solid cone: centre of mass at h/4, I_cm about a horizontal axis
  // m (3/20 b^2 + 3/80 h^2); pivot on the far base edge at distance rho
  const double b = 0.5 * base_width;
  const double h_cm = 0.25 * height;
  const double rho = std::hypot(b, h_cm);
  const double i_cm = mass * (3.0 / 20.0 * b * b + 3.0 / 80.0 * height * height);
  const double i_edge = i_cm + mass * rho * rho;
  // energy to lift the centre of mass over the edge: m g (rho - h_cm);
  // kinetic energy after the impulse: (J hit_height)^2 / (2 I_edge)
  const double lift = mass * kGravity * (rho - h_cm);
  return std::sqrt(2.0 * i_edge * lift) / hit_height;
}

struct ConeWorld::Impl : public b2ContactListener {
  ConeWorldParams params;
  Footprint footprint;
  std::vector<Cone> cones;

  // Box2D works in float: its frame is the map frame shifted by `origin` (the
  // centre of the cones' bounding box) so that float steps stay fine (< 4 um
  // within 64 m of it). Cone positions are reported as input + (b2 position -
  // b2 start position), exact while a cone has not moved.
  Vec2 origin;
  b2World b2world{b2Vec2(0.0f, 0.0f)};
  b2Body* ground = nullptr;
  b2Body* car = nullptr;

  // per cone
  std::vector<const ConeSpec*> spec;
  std::vector<b2Body*> body;          // nullptr while the cone is not in the Box2D world
  std::vector<b2Vec2> start;          // Box2D start position
  std::vector<b2Vec2> home;           // Box2D position the out test measures from (start, or where the wind left it)
  std::vector<b2Vec2> rest_pos;       // Box2D position while out of the world
  std::vector<float> rest_angle;      // rad, Box2D angle while out of the world
  std::vector<Vec2> position;         // current map position
  std::vector<double> radius;         // m, half the base width
  std::vector<double> step_impulse;   // N s, summed over this step's contacts
  std::vector<double> rest;           // s at rest
  std::vector<std::uint8_t> is_active, off_grid, knocked, doo;
  std::vector<std::uint8_t> external;  // moving by an outside cause (disturb_cone): its DOO is not the car's
  std::vector<std::int64_t> doo_step, doo_time;
  std::vector<int> active;    // awake cones, in the order they woke
  std::vector<int> moved;     // cones taken off the grid (in the world at least once)
  std::vector<int> in_world;  // cones that are Box2D bodies now
  std::vector<DooEvent> events;
  std::vector<int> scratch;
  double max_radius = 0.0;

  // uniform grid (compressed rows) of the cones at their start positions
  double gx0 = 0.0, gy0 = 0.0, cell = kCellSize;
  int nx = 1, ny = 1;
  std::vector<int> cell_begin;  // nx*ny + 1
  std::vector<int> cell_cones;

  // car
  Pose2 pose;
  bool have_pose = false;
  double car_reach = 0.0;  // m, farthest footprint corner from the base origin
  // the last clearance query: car-to-cone-edge clearance at the query pose and
  // a bound on how far any footprint point moved since
  bool query_valid = false;
  double query_clearance = 0.0;
  double moved_since_query = 0.0;

  std::int64_t steps = 0;
  std::int64_t time_ns = 0;
  ConeWorldStats stats;

  Impl(std::vector<Cone> cones_in, const ConeWorldParams& p, const Footprint& fp);
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  b2Vec2 to_b2(Vec2 p) const { return b2Vec2(static_cast<float>(p.x - origin.x), static_cast<float>(p.y - origin.y)); }
  int cone_of(b2Fixture* f) const { return static_cast<int>(f->GetBody()->GetUserData().pointer) - 1; }
  void activate(int i);
  void build_grid();
  void add_body(int i);
  void remove_body(int i);
  Box car_box(const Pose2& p, double grow) const;
  // the clearance (m) between the car footprint at p and the edge of cone i
  double car_gap(const Pose2& p, int i) const {
    const Vec2 q = p.inverse_transform(position[i]);
    return rect_distance(footprint, q) - radius[i];
  }
  template <class F>
  void visit(const Box& b, F&& f) const;
  double clearance(const Pose2& p);
  void box2d_step(const Pose2& from, const Pose2& to, double dyaw, double dt, double motion);
  void after_box2d_step(const Pose2& to, double dt, double motion);

  // b2ContactListener: a contact that starts touching wakes its cones;
  // PostSolve reports the impulses of each solved contact (also TOI sub-steps)
  void BeginContact(b2Contact* c) override {
    const int a = cone_of(c->GetFixtureA()), b = cone_of(c->GetFixtureB());
    if (a >= 0) activate(a);
    if (b >= 0) activate(b);
  }
  void PostSolve(b2Contact* c, const b2ContactImpulse* imp) override {
    double j = 0.0;
    for (int k = 0; k < imp->count; ++k) j += static_cast<double>(imp->normalImpulses[k]);
    const int a = cone_of(c->GetFixtureA()), b = cone_of(c->GetFixtureB());
    if (a >= 0) { activate(a); step_impulse[a] += j; }
    if (b >= 0) { activate(b); step_impulse[b] += j; }
    // a cone pushed by a cone the wind moves moves by the wind too
    if (a >= 0 && b >= 0 && (external[a] || external[b])) external[a] = external[b] = 1;
  }
};

ConeWorld::Impl::Impl(std::vector<Cone> cones_in, const ConeWorldParams& p, const Footprint& fp)
    : params(p), footprint(fp), cones(std::move(cones_in)) {
  params::require_valid(params, "ConeWorldParams");
  if (!(fp.rear + fp.front > 0.05 && fp.half_width > 0.05 && finite(fp.rear) && finite(fp.front) &&
        finite(fp.half_width))) {
    throw std::invalid_argument("Footprint: front + rear and half_width must be finite and > 0.05 m");
  }
  const int n = static_cast<int>(cones.size());
  for (int i = 0; i < n; ++i) {
    if (!finite(cones[i].position.x) || !finite(cones[i].position.y)) {
      throw std::invalid_argument("ConeWorld: cone " + std::to_string(i) + " has a non-finite position");
    }
  }

  // Box2D's frame origin: centre of the cones' bounding box
  if (n > 0) {
    double x0 = cones[0].position.x, x1 = x0, y0 = cones[0].position.y, y1 = y0;
    for (const Cone& c : cones) {
      x0 = std::min(x0, c.position.x); x1 = std::max(x1, c.position.x);
      y0 = std::min(y0, c.position.y); y1 = std::max(y1, c.position.y);
    }
    origin = {0.5 * (x0 + x1), 0.5 * (y0 + y1)};
  }

  b2world.SetAllowSleeping(true);
  b2world.SetContinuousPhysics(true);
  b2world.SetContactListener(this);

  // the ground: a static body without shapes, the anchor of every friction joint
  b2BodyDef ground_def;
  ground = b2world.CreateBody(&ground_def);

  // the car: a kinematic box. Box2D pads polygons by b2_polygonRadius, so the
  // box is shrunk by that much to make the collision outline the footprint.
  {
    b2BodyDef def;
    def.type = b2_kinematicBody;
    def.awake = true;
    car = b2world.CreateBody(&def);
    const double hx = 0.5 * (fp.front + fp.rear), hy = fp.half_width;
    const double skin = static_cast<double>(b2_polygonRadius);
    b2PolygonShape box;
    box.SetAsBox(static_cast<float>(hx - skin), static_cast<float>(hy - skin),
                 b2Vec2(static_cast<float>(0.5 * (fp.front - fp.rear)), 0.0f), 0.0f);
    b2FixtureDef fd;
    fd.shape = &box;
    fd.density = 0.0f;
    fd.friction = static_cast<float>(params.car_cone_friction);
    fd.restitution = static_cast<float>(params.car_cone_restitution);
    car->CreateFixture(&fd);
    car_reach = std::hypot(std::max(std::abs(fp.front), std::abs(fp.rear)), fp.half_width);
  }

  spec.resize(n);
  body.assign(n, nullptr);
  start.resize(n);
  home.resize(n);
  rest_pos.resize(n);
  rest_angle.assign(n, 0.0f);
  position.resize(n);
  radius.resize(n);
  step_impulse.assign(n, 0.0);
  rest.assign(n, 0.0);
  is_active.assign(n, 0);
  off_grid.assign(n, 0);
  knocked.assign(n, 0);
  external.assign(n, 0);
  doo.assign(n, 0);
  doo_step.assign(n, -1);
  doo_time.assign(n, -1);
  for (int i = 0; i < n; ++i) {
    spec[i] = cones[i].color == ConeColor::BigOrange ? &params.big_cone : &params.small_cone;
    radius[i] = 0.5 * spec[i]->base_width;
    max_radius = std::max(max_radius, radius[i]);
    position[i] = cones[i].position;
    start[i] = to_b2(cones[i].position);
    home[i] = start[i];
    rest_pos[i] = start[i];
  }
  build_grid();
  // without skipping, every cone is a body from the start: plain Box2D
  if (!params.skip_idle_steps) {
    for (int i = 0; i < n; ++i) add_body(i);
  }
}

// cone i becomes a Box2D body, asleep where it rests: a dynamic disc of the
// base's half width tied to the ground by a friction joint (Coulomb: force up
// to mu m g, torque up to mu m g times the base's mean radius)
void ConeWorld::Impl::add_body(int i) {
  if (body[i] != nullptr) return;
  const ConeSpec& s = *spec[i];
  const double r = radius[i];
  b2BodyDef def;
  def.type = b2_dynamicBody;
  def.position = rest_pos[i];
  def.angle = rest_angle[i];
  def.awake = false;
  def.allowSleep = true;
  def.userData.pointer = static_cast<uintptr_t>(i + 1);
  b2Body* b = b2world.CreateBody(&def);
  b2CircleShape disc;
  disc.m_radius = static_cast<float>(r);
  b2FixtureDef fd;
  fd.shape = &disc;
  fd.density = 1.0f;  // replaced by the mass data below
  fd.friction = static_cast<float>(params.car_cone_friction);
  fd.restitution = static_cast<float>(params.car_cone_restitution);
  b->CreateFixture(&fd);
  // mass and yaw inertia of a solid cone of base radius r: 3/10 m r^2
  b2MassData md;
  md.mass = static_cast<float>(s.mass);
  md.center = b2Vec2(0.0f, 0.0f);
  md.I = static_cast<float>(0.3 * s.mass * r * r);
  b->SetMassData(&md);
  b->SetAwake(false);

  const double normal = s.mass * kGravity;
  b2FrictionJointDef jd;
  jd.Initialize(ground, b, rest_pos[i]);
  jd.maxForce = static_cast<float>(params.ground_friction * normal);
  jd.maxTorque = static_cast<float>(params.ground_friction * normal * kSquareMeanRadius * r);
  jd.collideConnected = false;
  b2world.CreateJoint(&jd);

  body[i] = b;
  in_world.push_back(i);
  ++stats.bodies_created;
  // from now on its position is tracked in the moved list, not the grid
  if (!off_grid[i]) {
    off_grid[i] = 1;
    moved.push_back(i);
  }
}

// cone i (asleep, at rest, touching nothing) leaves the Box2D world
void ConeWorld::Impl::remove_body(int i) {
  b2Body* b = body[i];
  rest_pos[i] = b->GetPosition();
  rest_angle[i] = b->GetAngle();
  b2world.DestroyBody(b);  // also destroys its joint and contacts
  body[i] = nullptr;
  // never moved: back to the grid, so that the list of moved cones stays short
  if (rest_pos[i].x == start[i].x && rest_pos[i].y == start[i].y) {
    off_grid[i] = 0;
    moved.erase(std::find(moved.begin(), moved.end(), i));
  }
}

void ConeWorld::Impl::activate(int i) {
  if (!is_active[i]) {
    is_active[i] = 1;
    rest[i] = 0.0;
    active.push_back(i);
  }
}

void ConeWorld::Impl::build_grid() {
  const int n = static_cast<int>(cones.size());
  cell_begin.assign(2, 0);
  cell_cones.clear();
  if (n == 0) return;
  double x0 = cones[0].position.x, x1 = x0, y0 = cones[0].position.y, y1 = y0;
  for (const Cone& c : cones) {
    x0 = std::min(x0, c.position.x); x1 = std::max(x1, c.position.x);
    y0 = std::min(y0, c.position.y); y1 = std::max(y1, c.position.y);
  }
  cell = kCellSize;
  while (((x1 - x0) / cell + 1.0) * ((y1 - y0) / cell + 1.0) > kMaxCells) cell *= 2.0;
  gx0 = x0;
  gy0 = y0;
  nx = static_cast<int>((x1 - x0) / cell) + 1;
  ny = static_cast<int>((y1 - y0) / cell) + 1;
  const auto cell_of = [this](Vec2 p) {
    const int cx = std::clamp(static_cast<int>((p.x - gx0) / cell), 0, nx - 1);
    const int cy = std::clamp(static_cast<int>((p.y - gy0) / cell), 0, ny - 1);
    return cy * nx + cx;
  };
  // counting sort of the cones by cell (stable: cone order within a cell)
  cell_begin.assign(static_cast<size_t>(nx) * ny + 1, 0);
  for (const Cone& c : cones) ++cell_begin[cell_of(c.position) + 1];
  for (size_t k = 1; k < cell_begin.size(); ++k) cell_begin[k] += cell_begin[k - 1];
  cell_cones.resize(n);
  std::vector<int> fill(cell_begin.begin(), cell_begin.end() - 1);
  for (int i = 0; i < n; ++i) cell_cones[fill[cell_of(cones[i].position)]++] = i;
}

// the bounding box of the footprint at pose p, grown by `grow` (m)
Box ConeWorld::Impl::car_box(const Pose2& p, double grow) const {
  Box b{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
        -std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  for (const Vec2 corner : {Vec2{-footprint.rear, -footprint.half_width}, Vec2{-footprint.rear, footprint.half_width},
                            Vec2{footprint.front, -footprint.half_width}, Vec2{footprint.front, footprint.half_width}}) {
    const Vec2 w = p.transform(corner);
    b.x0 = std::min(b.x0, w.x); b.x1 = std::max(b.x1, w.x);
    b.y0 = std::min(b.y0, w.y); b.y1 = std::max(b.y1, w.y);
  }
  return {b.x0 - grow, b.y0 - grow, b.x1 + grow, b.y1 + grow};
}

// call f(i) for every resting cone whose grid cell meets box b, and for every
// cone off the grid (few: the ones that have been in the Box2D world)
template <class F>
void ConeWorld::Impl::visit(const Box& b, F&& f) const {
  if (!cones.empty()) {
    const double fx0 = (b.x0 - gx0) / cell, fx1 = (b.x1 - gx0) / cell;
    const double fy0 = (b.y0 - gy0) / cell, fy1 = (b.y1 - gy0) / cell;
    if (fx1 >= 0.0 && fy1 >= 0.0 && fx0 < nx && fy0 < ny) {
      // clamp in double first: a far-away box must not overflow the int cast
      const int cx0 = fx0 <= 0.0 ? 0 : static_cast<int>(fx0);
      const int cy0 = fy0 <= 0.0 ? 0 : static_cast<int>(fy0);
      const int cx1 = fx1 >= nx - 1 ? nx - 1 : static_cast<int>(fx1);
      const int cy1 = fy1 >= ny - 1 ? ny - 1 : static_cast<int>(fy1);
      for (int cy = cy0; cy <= cy1; ++cy) {
        const int row = cy * nx;
        for (int k = cell_begin[row + cx0]; k < cell_begin[row + cx1 + 1]; ++k) {
          const int i = cell_cones[k];
          if (!off_grid[i]) f(i);
        }
      }
    }
  }
  for (const int i : moved) f(i);
}

// the clearance (m) between the footprint at pose p and the nearest cone edge,
// exact for cones within query_reach of the footprint, else query_reach - r_max
double ConeWorld::Impl::clearance(const Pose2& p) {
  ++stats.proximity_queries;
  double best = params.query_reach - max_radius;
  visit(car_box(p, params.query_reach), [&](int i) { best = std::min(best, car_gap(p, i)); });
  return best;
}

void ConeWorld::Impl::box2d_step(const Pose2& from, const Pose2& to, double dyaw, double dt, double motion) {
  // bring into the world every cone the car or a moving cone can reach in this
  // step: within world_margin (+ this step's motion) of the car's end pose, or
  // of an awake cone (+ its travel in this step)
  if (params.skip_idle_steps) {
    const double reach = params.world_margin + motion;
    scratch.clear();
    visit(car_box(to, reach + max_radius), [&](int i) {
      if (body[i] == nullptr && car_gap(to, i) < reach) scratch.push_back(i);
    });
    for (const int j : active) {
      const b2Vec2 v = body[j]->GetLinearVelocity();
      const double cone_reach = params.world_margin + 2.0 * dt * std::hypot(static_cast<double>(v.x), static_cast<double>(v.y));
      const Vec2 c = position[j];
      const double g = radius[j] + cone_reach + max_radius;
      visit(Box{c.x - g, c.y - g, c.x + g, c.y + g}, [&](int i) {
        if (body[i] == nullptr && distance(position[i], c) - radius[i] - radius[j] < cone_reach) scratch.push_back(i);
      });
    }
    // in index order, once each: the world's body order must not depend on
    // the order of the visits above
    std::sort(scratch.begin(), scratch.end());
    scratch.erase(std::unique(scratch.begin(), scratch.end()), scratch.end());
    for (const int i : scratch) add_body(i);
  }

  // the car starts the step at `from` and moves with the velocity that brings
  // it to `to` in dt: Box2D integrates a kinematic body's origin (its centre of
  // mass is the origin) and angle linearly, so it arrives there, and the
  // contacts and the TOI sweep see the real motion
  car->SetTransform(to_b2(from.position()), static_cast<float>(wrap_angle(from.yaw)));
  car->SetLinearVelocity(b2Vec2(static_cast<float>((to.x - from.x) / dt), static_cast<float>((to.y - from.y) / dt)));
  car->SetAngularVelocity(static_cast<float>(dyaw / dt));
  b2world.Step(static_cast<float>(dt), params.velocity_iterations, params.position_iterations);
  ++stats.box2d_steps;
  after_box2d_step(to, dt, motion);
  // cones may have moved: the next step asks the grid again
  query_valid = false;
}

void ConeWorld::Impl::after_box2d_step(const Pose2& to, double dt, double motion) {
  scratch.clear();  // cones that became DOO in this step
  size_t keep = 0;
  for (size_t k = 0; k < active.size(); ++k) {
    const int i = active[k];
    b2Body* b = body[i];
    // position: input + displacement in Box2D's frame (exactly 0 if unmoved)
    const b2Vec2 now = b->GetPosition();
    const Vec2 disp{static_cast<double>(now.x) - static_cast<double>(start[i].x),
                    static_cast<double>(now.y) - static_cast<double>(start[i].y)};
    position[i] = cones[i].position + disp;
    // knocked over: the impulse of this step exceeded what tips the cone
    if (step_impulse[i] > spec[i]->knock_impulse) {
      knocked[i] = 1;
      if (!doo[i] && !external[i]) {
        doo[i] = 1;
        scratch.push_back(i);
      }
    }
    step_impulse[i] = 0.0;
    // out: moved by more than its base radius from where it stood
    const Vec2 from_home{static_cast<double>(now.x) - static_cast<double>(home[i].x),
                         static_cast<double>(now.y) - static_cast<double>(home[i].y)};
    if (!doo[i] && !external[i] && squared_norm(from_home) > radius[i] * radius[i]) {
      doo[i] = 2;
      scratch.push_back(i);
    }
    // at rest with nothing touching it: put it to sleep now
    bool awake = b->IsAwake();
    if (awake) {
      const b2Vec2 v = b->GetLinearVelocity();
      bool still = static_cast<double>(v.x) * v.x + static_cast<double>(v.y) * v.y <= params.rest_speed * params.rest_speed &&
                   std::abs(static_cast<double>(b->GetAngularVelocity())) <= params.rest_spin;
      for (b2ContactEdge* e = b->GetContactList(); still && e != nullptr; e = e->next) {
        if (e->contact->IsTouching()) still = false;
      }
      rest[i] = still ? rest[i] + dt : 0.0;
      if (still && rest[i] >= params.rest_time) {
        b->SetAwake(false);
        awake = false;
      }
    }
    if (awake) {
      active[keep++] = i;
    } else {
      is_active[i] = 0;
      // the wind's cone at rest: where it stands now is its place
      if (external[i]) {
        external[i] = 0;
        home[i] = now;
      }
    }
  }
  active.resize(keep);
  // cones that became DOO in the same step: by index
  std::sort(scratch.begin(), scratch.end());
  for (const int i : scratch) {
    doo_step[i] = steps;
    doo_time[i] = time_ns;
    events.push_back({i, steps, time_ns, doo[i] == 1 ? DooCause::Knocked : DooCause::Displaced});
  }

  // take out of the world the cones that sleep, touch nothing and are well
  // away (2 world_margin) from the car and from every awake cone
  if (!params.skip_idle_steps) return;
  const double away = 2.0 * params.world_margin;
  keep = 0;
  for (size_t k = 0; k < in_world.size(); ++k) {
    const int i = in_world[k];
    bool out = !is_active[i] && !body[i]->IsAwake() && car_gap(to, i) > away + motion;
    for (size_t a = 0; out && a < active.size(); ++a) {
      const int j = active[a];
      if (distance(position[i], position[j]) - radius[i] - radius[j] <= away) out = false;
    }
    for (b2ContactEdge* e = out ? body[i]->GetContactList() : nullptr; e != nullptr; e = e->next) {
      if (e->contact->IsTouching()) out = false;
    }
    if (out) {
      remove_body(i);
    } else {
      in_world[keep++] = i;
    }
  }
  in_world.resize(keep);
}

ConeWorld::ConeWorld(std::vector<Cone> cones, const ConeWorldParams& params, const Footprint& footprint)
    : impl_(std::make_unique<Impl>(std::move(cones), params, footprint)) {}
ConeWorld::~ConeWorld() = default;
ConeWorld::ConeWorld(ConeWorld&&) noexcept = default;
ConeWorld& ConeWorld::operator=(ConeWorld&&) noexcept = default;

void ConeWorld::step(const Pose2& car_pose, double car_vx_world, double car_vy_world, double yaw_rate, double dt) {
  Impl& w = *impl_;
  if (!(finite(car_pose.x) && finite(car_pose.y) && finite(car_pose.yaw) && finite(car_vx_world) &&
        finite(car_vy_world) && finite(yaw_rate) && finite(dt) && dt > 0.0)) {
    ++w.stats.rejected_steps;
    return;
  }
  ++w.steps;
  ++w.stats.steps;
  w.time_ns += std::llround(dt * 1e9);

  // where the car was at the start of this step
  const Pose2 from = w.have_pose ? w.pose
                                 : Pose2{car_pose.x - car_vx_world * dt, car_pose.y - car_vy_world * dt,
                                         car_pose.yaw - yaw_rate * dt};
  const double dyaw = wrap_angle(car_pose.yaw - from.yaw);
  // no footprint point moves farther than this during the step
  // (a step's few cm: plain_norm)
  const double motion = plain_norm(Vec2{car_pose.x - from.x, car_pose.y - from.y}) + std::abs(dyaw) * w.car_reach;
  w.pose = car_pose;
  w.have_pose = true;

  bool need = !w.params.skip_idle_steps || !w.active.empty();
  if (!need) {
    // every pose of this step is within moved_since_query of the query pose,
    // so its clearance is at least query_clearance - moved_since_query
    w.moved_since_query += motion;
    if (!w.query_valid || w.query_clearance - w.moved_since_query < w.params.wake_margin) {
      w.query_clearance = w.clearance(car_pose);
      w.moved_since_query = 0.0;
      w.query_valid = true;
      // the start of the step lies within `motion` of the queried end pose
      need = w.query_clearance - motion < w.params.wake_margin;
    }
  }
  if (need) w.box2d_step(from, car_pose, dyaw, dt, motion);
}

void ConeWorld::kick_cone(int i, Vec2 velocity) {
  Impl& w = *impl_;
  if (i < 0 || i >= cone_count()) throw std::out_of_range("ConeWorld::kick_cone: no cone " + std::to_string(i));
  if (!finite(velocity.x) || !finite(velocity.y)) return;
  w.add_body(i);
  w.body[i]->SetLinearVelocity(b2Vec2(static_cast<float>(velocity.x), static_cast<float>(velocity.y)));
  w.body[i]->SetAwake(true);
  w.activate(i);
  w.query_valid = false;
}

void ConeWorld::disturb_cone(int i, Vec2 shift, bool topple) {
  Impl& w = *impl_;
  if (i < 0 || i >= cone_count()) throw std::out_of_range("ConeWorld::disturb_cone: no cone " + std::to_string(i));
  if (!finite(shift.x) || !finite(shift.y)) return;
  if (topple) w.knocked[i] = 1;
  const double d = norm(shift);
  if (d <= 0.0) return;
  // Coulomb friction decelerates at mu g: v^2 = 2 mu g d
  const double decel = w.params.ground_friction * kGravity;
  const double speed = decel > 0.0 ? std::sqrt(2.0 * decel * d) : d;
  w.external[i] = 1;
  kick_cone(i, shift * (speed / d));
}

int ConeWorld::cone_count() const { return static_cast<int>(impl_->cones.size()); }
const Cone& ConeWorld::cone(int i) const { return impl_->cones.at(i); }
Vec2 ConeWorld::cone_position(int i) const { return impl_->position.at(i); }
bool ConeWorld::cone_knocked(int i) const { return impl_->knocked.at(i) != 0; }
bool ConeWorld::cone_doo(int i) const { return impl_->doo.at(i) != 0; }
int ConeWorld::doo_count() const { return static_cast<int>(impl_->events.size()); }
std::vector<int> ConeWorld::doo_cones() const {
  std::vector<int> out;
  out.reserve(impl_->events.size());
  for (const DooEvent& e : impl_->events) out.push_back(e.cone);
  return out;
}
const std::vector<DooEvent>& ConeWorld::doo_events() const { return impl_->events; }
std::int64_t ConeWorld::doo_step(int i) const { return impl_->doo_step.at(i); }
std::int64_t ConeWorld::doo_time_ns(int i) const { return impl_->doo_time.at(i); }
int ConeWorld::bodies_in_world() const { return static_cast<int>(impl_->in_world.size()); }
Pose2 ConeWorld::car_pose() const { return impl_->pose; }
std::int64_t ConeWorld::time_ns() const { return impl_->time_ns; }
const ConeWorldStats& ConeWorld::stats() const { return impl_->stats; }
const ConeWorldParams& ConeWorld::params() const { return impl_->params; }
const Footprint& ConeWorld::footprint() const { return impl_->footprint; }

}  // namespace paddock::world
