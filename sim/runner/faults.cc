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
  std::stable_sort(n.begin(), n.end(), [](const FaultNote& a, const FaultNote& b) { return a.at < b.at; });
  return n;
}

void FaultInjector::filter_lidar(double t, std::vector<sensors::LidarPoint>& points) const {
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
