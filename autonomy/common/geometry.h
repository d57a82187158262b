#pragma once
// plane geometry value types shared by every module: vectors, poses, angles.
#include <algorithm>
#include <cmath>

namespace paddock {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kGravity = 9.81;  // m/s^2

struct Vec2 {
  double x = 0.0;
  double y = 0.0;

  constexpr Vec2() = default;
  constexpr Vec2(double x_, double y_) : x(x_), y(y_) {}
  constexpr Vec2 operator+(Vec2 o) const { return {x + o.x, y + o.y}; }
  constexpr Vec2 operator-(Vec2 o) const { return {x - o.x, y - o.y}; }
  constexpr Vec2 operator-() const { return {-x, -y}; }
  constexpr Vec2 operator*(double s) const { return {x * s, y * s}; }
  constexpr Vec2 operator/(double s) const { return {x / s, y / s}; }
  Vec2& operator+=(Vec2 o) { x += o.x; y += o.y; return *this; }
  Vec2& operator-=(Vec2 o) { x -= o.x; y -= o.y; return *this; }
  constexpr bool operator==(Vec2 o) const { return x == o.x && y == o.y; }
};

inline constexpr Vec2 operator*(double s, Vec2 v) { return {s * v.x, s * v.y}; }
inline constexpr double dot(Vec2 a, Vec2 b) { return a.x * b.x + a.y * b.y; }
// z component of the 3D cross product: > 0 when b is counter-clockwise of a
inline constexpr double cross(Vec2 a, Vec2 b) { return a.x * b.y - a.y * b.x; }
inline double norm(Vec2 v) { return std::hypot(v.x, v.y); }
inline constexpr double squared_norm(Vec2 v) { return v.x * v.x + v.y * v.y; }
// |v| as sqrt(x^2 + y^2): for lengths of a track's scale, which need none of
// hypot's guard against overflow and underflow, at a fraction of its cost
// (not norm()'s bits)
inline double plain_norm(Vec2 v) { return std::sqrt(squared_norm(v)); }

inline double distance(Vec2 a, Vec2 b) { return norm(a - b); }
inline Vec2 unit_from_angle(double a) { return {std::cos(a), std::sin(a)}; }
inline double angle_of(Vec2 v) { return std::atan2(v.y, v.x); }
// counter-clockwise rotation by angle a
inline Vec2 rotate(Vec2 v, double a) {
  const double c = std::cos(a), s = std::sin(a);
  return {c * v.x - s * v.y, s * v.x + c * v.y};
}
// left normal (v rotated by +90 degrees)
inline constexpr Vec2 left_normal(Vec2 v) { return {-v.y, v.x}; }

// an axis-aligned box grown point by point (a point with a coordinate that is
// not finite is left out); empty, near nothing, until a point is added. For
// the candidates of a nearest-neighbour search over a small region: near()
// takes the reach a hair wider (1e-9 relative) so that no point whose
// computed distance is within the reach is left out by rounding
struct Box {
  double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;

  void add(Vec2 p) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) return;
    x0 = std::min(x0, p.x);
    y0 = std::min(y0, p.y);
    x1 = std::max(x1, p.x);
    y1 = std::max(y1, p.y);
  }
  // p within `reach` of the box along each axis
  bool near(Vec2 p, double reach) const {
    const double r = reach * (1.0 + 1e-9);
    return p.x >= x0 - r && p.x <= x1 + r && p.y >= y0 - r && p.y <= y1 + r;
  }
};

// angle wrapped into [-pi, pi) (fmod only when a + pi lies outside [0, 2 pi):
// inside, fmod would return it unchanged, exactly)
inline double wrap_angle(double a) {
  a += kPi;
  if (!(a >= 0.0 && a < 2.0 * kPi)) {
    a = std::fmod(a, 2.0 * kPi);
    if (a < 0.0) a += 2.0 * kPi;
  }
  return a - kPi;
}

// a rigid 2D pose: position and yaw (counter-clockwise from +x)
struct Pose2 {
  double x = 0.0;
  double y = 0.0;
  double yaw = 0.0;

  Vec2 position() const { return {x, y}; }
  Vec2 heading() const { return unit_from_angle(yaw); }
  // a point given in this pose's frame, expressed in the parent frame
  Vec2 transform(Vec2 p) const { return position() + rotate(p, yaw); }
  // a parent-frame point, expressed in this pose's frame
  Vec2 inverse_transform(Vec2 p) const { return rotate(p - position(), -yaw); }
};

// s (+) d: the pose d, given in s's frame, in s's parent frame
inline Pose2 compose(const Pose2& s, const Pose2& d) {
  const Vec2 p = s.transform({d.x, d.y});
  return {p.x, p.y, wrap_angle(s.yaw + d.yaw)};
}
// a^-1 (+) b: the pose b in a's frame (the motion from a to b)
inline Pose2 between(const Pose2& a, const Pose2& b) {
  const Vec2 d = a.inverse_transform(b.position());
  return {d.x, d.y, wrap_angle(b.yaw - a.yaw)};
}

// the pose a fraction f of the way from a to b (position linear, yaw on the circle)
inline Pose2 interpolate(const Pose2& a, const Pose2& b, double f) {
  return {a.x + f * (b.x - a.x), a.y + f * (b.y - a.y), wrap_angle(a.yaw + f * wrap_angle(b.yaw - a.yaw))};
}

// no NaN and no infinity in a value: the first check of every module's input
inline bool finite(double v) { return std::isfinite(v); }
inline bool finite(Vec2 p) { return std::isfinite(p.x) && std::isfinite(p.y); }
inline bool finite(const Pose2& p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.yaw); }

// a directed segment from a to b
struct Segment {
  Vec2 a;
  Vec2 b;
};

}  // namespace paddock
