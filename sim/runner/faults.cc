#include "sim/runner/faults.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "autonomy/common/geometry.h"

namespace paddock::runner {

namespace {

std::string window(const FaultWindow& w) {
  char b[64];
  if (w.duration > 0.0) {
    std::snprintf(b, sizeof b, " for %.3g s", w.duration);
    return b;
  }
  return " to the end";
}

std::string num(double v) { return params::number(v); }

// azimuth a within the sector from `from` counter-clockwise to `to`
bool in_sector(double a, double from, double to) {
  const double span = std::fmod(to - from + 4.0 * kPi, 2.0 * kPi);
  const double off = std::fmod(a - from + 4.0 * kPi, 2.0 * kPi);
  return off <= span;
}

// the centreline point `along` m from its start (the last point past its
// end), its heading and its index; the centreline has >= 2 points
struct Station {
  Vec2 at;
  double yaw = 0.0;
  std::size_t i = 1;
};
Station station(const std::vector<Vec2>& line, double along) {
  std::size_t i = 1;
  double s = 0.0;
  while (i + 1 < line.size() && s + distance(line[i - 1], line[i]) < along) {
    s += distance(line[i - 1], line[i]);
    ++i;
  }
  const Vec2 a = line[i - 1], b = line[i];
  return {a, std::atan2(b.y - a.y, b.x - a.x), i};
}

}  // namespace

std::vector<FaultNote> fault_notes(const FaultsSection& f) {
  std::vector<FaultNote> n;
  if (f.lidar.at) {
    std::string what = "LiDAR dropout: ";
    if (f.lidar.mode == LidarDropout::Rotations) what += "no packets";
    if (f.lidar.mode == LidarDropout::Sector) what += "no returns in azimuth [" + num(f.lidar.sector_from) + ", " + num(f.lidar.sector_to) + "] rad";
    if (f.lidar.mode == LidarDropout::Rings) what += "no returns from rings " + std::to_string(f.lidar.ring_first) + ".." + std::to_string(f.lidar.ring_last);
    n.push_back({"lidar", what + window(f.lidar), *f.lidar.at});
  }
  if (f.camera.at)
    n.push_back({"camera", std::string("camera ") + (f.camera.mode == CameraFaultMode::Dead ? "dead" : "frozen") + window(f.camera), *f.camera.at});
  if (f.imu.at) {
    n.push_back({"imu", "IMU bias step (" + num(f.imu.bias_ax) + ", " + num(f.imu.bias_ay) + ") m/s^2, " + num(f.imu.bias_yaw_rate) +
                            " rad/s; spikes " + num(f.imu.spike_rate) + " Hz" + window(f.imu), *f.imu.at});
  }
  if (f.wheel.at) {
    static const char* const names[] = {"front left", "front right", "rear left", "rear right"};
    n.push_back({"wheel", std::string(names[std::clamp(f.wheel.wheel, 0, 3)]) + " wheel speed " +
                              (f.wheel.mode == WheelFaultMode::Stuck ? "stuck" : "noisy (" + num(f.wheel.noise) + " rad/s)") + window(f.wheel),
                 *f.wheel.at});
  }
  if (f.steering.at) {
    n.push_back({"steering", std::string("steering ") + (f.steering.mode == SteeringFaultMode::Sensor ? "sensor" : "actuator") +
                                 " offset " + num(f.steering.offset) + " rad" + window(f.steering),
                 *f.steering.at});
  }
  if (f.control.at) n.push_back({"control", "the stack's computer stalls" + window(f.control), *f.control.at});
  if (f.can.at) n.push_back({"can", num(100.0 * f.can.loss) + " % of the VCU's CAN frames lost" + window(f.can), *f.can.at});
  if (f.res.at) n.push_back({"res", "RES emergency stop pressed", *f.res.at});
  if (f.ebs.at) n.push_back({"ebs", "EBS tank pressure drops to " + num(f.ebs.pressure) + " bar", *f.ebs.at});
  if (f.cones.at) n.push_back({"cones", std::to_string(f.cones.wrong_colour) + " cones of the wrong colour (blue and yellow swapped)", *f.cones.at});
  if (f.object.at) {
    n.push_back({"object", std::string(f.object.kind == ObjectKind::Bag ? "a bag" : "a person's legs") + " by the " +
                               (f.object.left ? "left" : "right") + " boundary, " + num(f.object.along) + " m along the centreline",
                 *f.object.at});
  }
  if (f.rain.at) {
    n.push_back({"rain", "rain: " + num(100.0 * f.rain.returns_lost) + " % of the LiDAR's returns lost, grip x " + num(f.rain.grip) + window(f.rain),
                 *f.rain.at});
  }
  if (f.wind.at) {
    n.push_back({"wind", "a gust moves the cones within " + num(f.wind.radius) + " m of the centreline " + num(f.wind.along) +
                             " m along it, by " + num(f.wind.slide) + " m, " + num(100.0 * f.wind.topple) + " % toppled",
                 *f.wind.at});
  }
  std::stable_sort(n.begin(), n.end(), [](const FaultNote& a, const FaultNote& b) { return a.at < b.at; });
  return n;
}

void FaultInjector::place(const world::TrackModel& track, const std::vector<Cone>& cones) {
  object_.clear();
  recoloured_.clear();
  if (f_.object.at && track.centreline.size() >= 2) {
    // the centreline point `along` m from its start, and its normal
    const auto [a, yaw, i] = station(track.centreline, f_.object.along);
    const Vec2 normal{-std::sin(yaw), std::cos(yaw)};  // left
    const double half = i < track.width.size() ? 0.5 * track.width[i] : 1.5;
    const Vec2 at = a + normal * ((f_.object.left ? 1.0 : -1.0) * (half + f_.object.edge_offset));
    if (f_.object.kind == ObjectKind::Bag) {
      object_.push_back({at, yaw, 0.4, 0.3, 0.3});
    } else {
      const Vec2 d{std::cos(yaw), std::sin(yaw)};
      object_.push_back({at + d * 0.125, yaw, 0.12, 0.12, 0.9});
      object_.push_back({at - d * 0.125, yaw, 0.12, 0.12, 0.9});
    }
  }
  if (f_.cones.at && f_.cones.wrong_colour > 0) {
    std::vector<int> sides;
    for (std::size_t i = 0; i < cones.size(); ++i)
      if (cones[i].color == ConeColor::Blue || cones[i].color == ConeColor::Yellow) sides.push_back(static_cast<int>(i));
    // a seeded partial shuffle: the first wrong_colour of them
    const std::size_t n = std::min(sides.size(), static_cast<std::size_t>(f_.cones.wrong_colour));
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t j = k + static_cast<std::size_t>(rng_() % (sides.size() - k));
      std::swap(sides[k], sides[j]);
    }
    recoloured_.assign(sides.begin(), sides.begin() + static_cast<std::ptrdiff_t>(n));
    std::sort(recoloured_.begin(), recoloured_.end());
  }
  gust_.clear();
  gust_done_ = false;
  if (f_.wind.at && track.centreline.size() >= 2) {
    // every cone within `radius` of the point, by index: a slide of 0.5-1.5
    // times the mean, a direction within 0.2 rad of the wind's
    const Station st = station(track.centreline, f_.wind.along);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (std::size_t i = 0; i < cones.size(); ++i) {
      if (distance(cones[i].position, st.at) > f_.wind.radius) continue;
      const double slide = f_.wind.slide * (0.5 + u(rng_));
      const double dir = st.yaw + f_.wind.direction + 0.2 * (2.0 * u(rng_) - 1.0);
      const bool topple = u(rng_) < f_.wind.topple;
      gust_.push_back({static_cast<int>(i), Vec2{std::cos(dir), std::sin(dir)} * slide, topple});
    }
  }
}

std::string FaultInjector::gust_words() const {
  const auto toppled = std::count_if(gust_.begin(), gust_.end(), [](const Gust& g) { return g.topple; });
  return std::to_string(gust_.size()) + " cones moved, " + std::to_string(toppled) + " of them toppled";
}

std::vector<FaultInjector::Gust> FaultInjector::gust_due(double t) {
  if (gust_done_ || !f_.wind.at || t < *f_.wind.at) return {};
  gust_done_ = true;
  return gust_;
}

ConeColor FaultInjector::colour(int i, ConeColor color, double t) const {
  if (!f_.cones.at || t < *f_.cones.at || !std::binary_search(recoloured_.begin(), recoloured_.end(), i)) return color;
  return color == ConeColor::Blue ? ConeColor::Yellow : color == ConeColor::Yellow ? ConeColor::Blue : color;
}

void FaultInjector::filter_lidar(double t, std::vector<sensors::LidarPoint>& points) {
  if (f_.rain.on(t) && f_.rain.returns_lost > 0.0) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    points.erase(std::remove_if(points.begin(), points.end(), [&](const sensors::LidarPoint&) { return u(rng_) < f_.rain.returns_lost; }),
                 points.end());
  }
  const LidarFault& l = f_.lidar;
  if (!l.on(t) || l.mode == LidarDropout::Rotations) return;
  const auto lost = [&l](const sensors::LidarPoint& p) {
    if (l.mode == LidarDropout::Rings) return p.ring >= l.ring_first && p.ring <= l.ring_last;
    return in_sector(std::atan2(static_cast<double>(p.y), static_cast<double>(p.x)), l.sector_from, l.sector_to);
  };
  points.erase(std::remove_if(points.begin(), points.end(), lost), points.end());
}

void FaultInjector::apply(double t, hal::Imu& m, double period) {
  const ImuFault& f = f_.imu;
  if (!f.on(t)) return;
  m.ax += f.bias_ax;
  m.ay += f.bias_ay;
  m.yaw_rate += f.bias_yaw_rate;
  if (f.spike_rate > 0.0 && std::uniform_real_distribution<double>(0.0, 1.0)(rng_) < f.spike_rate * period) {
    const double sign = rng_() % 2 == 0 ? 1.0 : -1.0;
    m.ax += sign * f.spike_accel;
    m.ay -= sign * f.spike_accel;
    m.yaw_rate += sign * f.spike_yaw_rate;
  }
}

void FaultInjector::apply(double t, hal::WheelSpeeds& m) {
  const WheelFault& f = f_.wheel;
  const auto w = static_cast<std::size_t>(std::clamp(f.wheel, 0, 3));
  if (!f.on(t)) {
    stuck_.reset();
    return;
  }
  if (f.mode == WheelFaultMode::Stuck) {
    if (!stuck_) stuck_ = m.omega[w];
    m.omega[w] = *stuck_;
  } else {
    m.omega[w] += std::normal_distribution<double>(0.0, f.noise)(rng_);
  }
}

void FaultInjector::apply(double t, hal::SteeringAngle& m) const {
  if (f_.steering.mode == SteeringFaultMode::Sensor && f_.steering.on(t)) m.angle += f_.steering.offset;
}

void FaultInjector::apply(double t, vehicle::DriverInput& in) const {
  if (f_.steering.mode == SteeringFaultMode::Actuator && f_.steering.on(t)) in.steering_angle += f_.steering.offset;
}

bool FaultInjector::can_delivers(double t) {
  if (!f_.can.on(t)) return true;
  return std::uniform_real_distribution<double>(0.0, 1.0)(rng_) >= f_.can.loss;
}

}  // namespace paddock::runner
