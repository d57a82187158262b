#include "autonomy/car/car.h"

#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <ctime>
#include <memory>
#include <ostream>
#include <stdexcept>
#include <vector>

#include "autonomy/car/camera.h"
#include "autonomy/hal/can_udp.h"
#include "autonomy/hal/image.h"
#include "autonomy/hal/udp.h"

namespace paddock::car {
namespace {

// a raw SocketCAN socket on one interface (the car's bus)
class SocketCan {
 public:
  explicit SocketCan(const std::string& interface) : name_(interface) {
    fd_ = ::socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
    if (fd_ < 0) fail("this kernel has no SocketCAN (" + std::string(std::strerror(errno)) + "; modprobe can_raw)");
    ifreq ifr{};
    if (interface.size() >= sizeof ifr.ifr_name) fail("the name is too long");
    std::memcpy(ifr.ifr_name, interface.c_str(), interface.size() + 1);
    if (::ioctl(fd_, SIOCGIFINDEX, &ifr) != 0) fail(std::strerror(errno));
    sockaddr_can a{};
    a.can_family = AF_CAN;
    a.can_ifindex = ifr.ifr_ifindex;
    if (::bind(fd_, reinterpret_cast<const sockaddr*>(&a), sizeof a) != 0) fail(std::strerror(errno));
  }
  ~SocketCan() {
    if (fd_ >= 0) ::close(fd_);
  }
  SocketCan(const SocketCan&) = delete;
  SocketCan& operator=(const SocketCan&) = delete;
  int fd() const { return fd_; }
  // the next frame waiting, if any
  std::optional<hal::CanFrame> receive(TimeNs now) {
    std::uint8_t bytes[hal::kSocketCanFrameSize];
    const ssize_t n = ::recv(fd_, bytes, sizeof bytes, MSG_DONTWAIT);
    if (n < 0) return std::nullopt;
    return hal::from_socketcan(bytes, static_cast<std::size_t>(n), now);
  }
  void send(const hal::CanFrame& f) {
    std::uint8_t bytes[hal::kSocketCanFrameSize];
    hal::to_socketcan(f, bytes);
    if (::write(fd_, bytes, sizeof bytes) != static_cast<ssize_t>(sizeof bytes))
      throw std::runtime_error("CAN interface " + name_ + ": cannot send: " + std::strerror(errno));
  }

 private:
  [[noreturn]] void fail(const std::string& why) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    throw std::runtime_error("no CAN interface '" + name_ + "': " + why +
                             " (ip link shows the interfaces; without one, leave [car] can_interface empty for CAN over UDP)");
  }
  int fd_ = -1;
  std::string name_;
};

TimeNs wall_now() {
  timespec ts{};
  ::clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<TimeNs>(ts.tv_sec) * kNsPerSecond + ts.tv_nsec;
}

// the log's JPEG quality for the frames a camera sends uncompressed
constexpr int kJpegQuality = 85;

// the node and what the car logs of it: every message as it is taken in,
// each cycle's command and outputs
struct Car {
  CarNode& node;
  CarLog* log = nullptr;

  void lidar_packet(TimeNs at, const std::vector<std::uint8_t>& p) {
    node.lidar_packet(at, p.data(), p.size());
    if (log) log->lidar_packet(at, p.data(), p.size());
  }
  void can_frame(TimeNs at, const hal::CanFrame& f) {
    node.can_frame(f);
    if (!log) return;
    std::uint8_t bytes[hal::kSocketCanFrameSize];
    hal::to_socketcan(f, bytes);
    log->can_frame(at, true, bytes);
  }
  // a camera frame; jpeg: its bytes when the camera sent JPEG (else the log encodes it)
  void camera(TimeNs at, hal::CameraFrame frame, const std::vector<std::uint8_t>& jpeg) {
    if (log && jpeg.empty()) log->image(at, frame, kJpegQuality);
    else if (log) log->image(at, frame.stamp, jpeg);
    node.camera_frame(std::move(frame));
  }
  void object(TimeNs at, const std::vector<std::uint8_t>& p) {
    const hal::SensorMessage* m = node.object(at, reinterpret_cast<const char*>(p.data()), p.size());
    if (log && m) log->message(at, *m);
  }
  // the control cycle: the command's frame, stamped `at`
  hal::CanFrame cycle(TimeNs at) {
    const hal::ActuatorCommand c = node.tick(at);
    hal::CanFrame f = node.command_frame(c);
    f.stamp = at;
    if (log) {
      std::uint8_t bytes[hal::kSocketCanFrameSize];
      hal::to_socketcan(f, bytes);
      log->can_frame(at, false, bytes);
      log->cycle(at, c, node.stack());
    }
    return f;
  }
};

void print_summary(std::ostream& out, const CarNode& node, long lockstep_datagrams) {
  const CarCounters c = node.counters();
  out << "paddock car: done after " << c.ticks << " control cycles, AS "
      << hal::to_string(node.stack().telemetry().as_state) << "\n";
  out << "  lidar    " << c.lidar_packets << " packets, " << c.lidar.rotations << " rotations; dropped: "
      << c.lidar.bad_size << " packets of a wrong size, " << c.lidar.bad_columns << " bad columns, "
      << c.lidar.late_columns << " late columns; " << c.lidar.lost_columns << " columns lost\n";
  out << "  can      " << c.can_frames << " frames; dropped: " << c.can.unknown_id << " unknown id, " << c.can.bad_dlc
      << " bad dlc, " << c.can.unmatched_imu_halves << " unmatched IMU halves\n";
  if (c.camera_frames > 0) out << "  camera   " << c.camera_frames << " frames\n";
  out << "  objects  " << c.objects << " messages, " << c.bad_objects << " dropped";
  if (!node.last_bad_object().empty()) out << " (last: " << node.last_bad_object() << ")";
  out << "\n";
  if (lockstep_datagrams > 0) out << "  lockstep " << lockstep_datagrams << " datagrams on the CAN channel\n";
  const std::string& fault = node.stack().telemetry().last_fault;
  out << "  fault    " << (fault.empty() ? "-" : fault) << "\n";
  out.flush();
}

// lock-step: the CAN channel's datagrams drive; the LiDAR's and the objects'
// are taken when a datagram counts them
void run_lockstep(const CarSetup& s, Car& car, hal::UdpSocket& lidar, hal::UdpSocket& can,
                  hal::UdpSocket& objects, std::ostream& out, const volatile std::sig_atomic_t* stop) {
  const TimeNs timeout = from_seconds(s.car.peer_timeout);
  std::vector<std::uint8_t> buf;
  std::uint32_t next_sequence = 0, lidar_taken = 0, objects_taken = 0, reply_sequence = 0;
  long datagrams = 0;
  bool started = false;
  for (;;) {
    if (stop && *stop) break;
    sockaddr_in from{};
    // before the first datagram the car waits for the simulator as long as it takes
    if (!can.receive(buf, started ? timeout : from_seconds(1.0), &from)) {
      if (!started) continue;
      if (stop && *stop) break;
      throw std::runtime_error("lock-step: no datagram from the simulator for " + std::to_string(s.car.peer_timeout) +
                               " s ([car] peer_timeout)");
    }
    std::string why;
    const std::optional<hal::CanDatagram> d = hal::decode_datagram(buf.data(), buf.size(), &why);
    if (!d) throw std::runtime_error("lock-step: a datagram on the CAN port that is none: " + why);
    if (d->sequence != next_sequence)
      throw std::runtime_error("lock-step: datagram " + std::to_string(d->sequence) + " came where " +
                               std::to_string(next_sequence) + " was due (lost or reordered)");
    started = true;
    ++next_sequence;
    ++datagrams;
    // what was sent before it, in order
    while (lidar_taken < d->lidar_before) {
      if (!lidar.receive(buf, timeout))
        throw std::runtime_error("lock-step: LiDAR packet " + std::to_string(lidar_taken) + " never came");
      car.lidar_packet(d->time, buf);
      ++lidar_taken;
    }
    while (objects_taken < d->objects_before) {
      if (!objects.receive(buf, timeout))
        throw std::runtime_error("lock-step: object message " + std::to_string(objects_taken) + " never came");
      car.object(d->time, buf);
      ++objects_taken;
    }
    for (const hal::CanFrame& f : d->frames) car.can_frame(d->time, f);
    hal::CanDatagram answer;
    answer.time = d->time;
    answer.sequence = reply_sequence;
    if (d->kind == hal::CanDatagram::Kind::Tick) {
      answer.kind = hal::CanDatagram::Kind::Reply;
      answer.frames.push_back(car.cycle(d->time));
    } else if (d->kind == hal::CanDatagram::Kind::Sync) {
      answer.kind = hal::CanDatagram::Kind::Ack;
    } else if (d->kind == hal::CanDatagram::Kind::End) {
      break;
    } else if (d->kind != hal::CanDatagram::Kind::Data) {
      throw std::runtime_error(std::string("lock-step: a ") + hal::to_string(d->kind) + " datagram from the simulator");
    } else {
      continue;
    }
    const std::vector<std::uint8_t> bytes = hal::encode(answer);
    can.send_to(from, bytes.data(), bytes.size());
    ++reply_sequence;
  }
  print_summary(out, car.node, datagrams);
}

// the car: its own clock, a control cycle every period
void run_wall(const CarSetup& s, Car& car, hal::UdpSocket& lidar, hal::UdpSocket* can_udp, SocketCan* can_bus,
              hal::UdpSocket& objects, V4l2Camera* camera, std::ostream& out, const volatile std::sig_atomic_t* stop) {
  std::vector<std::uint8_t> jpeg;
  std::vector<std::uint8_t> buf;
  std::optional<sockaddr_in> peer;  // CAN over UDP: where the commands go
  long bad_datagrams = 0;
  std::uint32_t sequence = 0;
  TimeNs next_tick = wall_now();
  const int can_fd = can_bus ? can_bus->fd() : can_udp->fd();
  while (!(stop && *stop)) {
    TimeNs now = wall_now();
    if (now < next_tick) {
      pollfd p[4] = {{lidar.fd(), POLLIN, 0}, {can_fd, POLLIN, 0}, {objects.fd(), POLLIN, 0},
                     {camera ? camera->fd() : -1, POLLIN, 0}};
      const TimeNs wait = next_tick - now;
      timespec ts{static_cast<time_t>(wait / kNsPerSecond), static_cast<long>(wait % kNsPerSecond)};
      if (::ppoll(p, camera ? 4 : 3, &ts, nullptr) < 0 && errno != EINTR)
        throw std::runtime_error(std::string("poll: ") + std::strerror(errno));
      now = wall_now();
    }
    while (lidar.receive(buf, 0)) car.lidar_packet(now, buf);
    if (can_bus) {
      while (const std::optional<hal::CanFrame> f = can_bus->receive(now)) car.can_frame(now, *f);
    } else {
      sockaddr_in from{};
      while (can_udp->receive(buf, 0, &from)) {
        const std::optional<hal::CanDatagram> d = hal::decode_datagram(buf.data(), buf.size());
        if (!d) {
          ++bad_datagrams;  // no CAN over UDP: dropped
          continue;
        }
        peer = from;
        for (hal::CanFrame f : d->frames) {
          f.stamp = now;  // on the car a frame is stamped when it is received
          car.can_frame(now, f);
        }
      }
    }
    while (objects.receive(buf, 0)) car.object(now, buf);
    if (camera) {
      while (std::optional<hal::CameraFrame> f = camera->read(now, &jpeg)) car.camera(now, std::move(*f), jpeg);
    }
    if (now < next_tick) continue;
    const hal::CanFrame command = car.cycle(now);
    if (can_bus) {
      can_bus->send(command);
    } else if (peer) {
      hal::CanDatagram d;
      d.time = now;
      d.sequence = sequence++;
      d.frames.push_back(command);
      const std::vector<std::uint8_t> bytes = hal::encode(d);
      can_udp->send_to(*peer, bytes.data(), bytes.size());
    }
    // a late cycle is not made up: the next one is a period after this one's due time, or now
    next_tick = std::max(next_tick + s.control_period, now);
  }
  print_summary(out, car.node, 0);
  if (can_udp) out << "  can/udp  " << bad_datagrams << " datagrams that were no CAN over UDP, dropped" << std::endl;
}

}  // namespace

void run_car(const CarSetup& s, std::ostream& out, const volatile std::sig_atomic_t* stop) {
  if (!s.dbc) throw std::invalid_argument("run_car: the car's DBC is needed");
  const std::string problem = params::validate(s.car);
  if (!problem.empty()) throw std::invalid_argument("[car] " + problem);
  // on the car's own clock the scans take the time their processing takes:
  // no modelled latency on top ([perception] latency is the simulation's)
  stack::StackParams stack = s.stack;
  if (s.car.clock == Clock::Wall) stack.perception.latency = 0.0;
  CarNode node(stack, s.mission, s.lidar, s.layout, *s.dbc, s.dbc_source, s.car.watchdog);
  hal::UdpSocket lidar(s.car.host, s.car.lidar_port);
  hal::UdpSocket objects(s.car.host, s.car.objects_port);
  std::optional<hal::UdpSocket> can_udp;
  std::optional<SocketCan> can_bus;
  if (s.car.can_interface.empty()) {
    can_udp.emplace(s.car.host, s.car.can_port);
  } else {
    can_bus.emplace(s.car.can_interface);
  }
  out << "paddock car: listening on " << s.car.host << ": lidar udp " << lidar.port() << ", can "
      << (can_udp ? "udp " + std::to_string(can_udp->port()) : "socketcan " + s.car.can_interface)
      << ", objects udp " << objects.port() << "; clock " << (s.car.clock == Clock::Lockstep ? "lockstep" : "wall")
      << std::endl;
  std::optional<V4l2Camera> camera;
  if (!s.car.camera_device.empty()) {
    camera.emplace(s.car.camera_device, s.camera_width, s.camera_height);
    out << "paddock car: camera " << s.car.camera_device << ", " << s.camera_width << "x" << s.camera_height << " "
        << camera->format() << std::endl;
  }
  std::unique_ptr<CarLog> log;
  if (!s.log_path.empty())
    log = std::make_unique<CarLog>(s.log_path, s.log_files, s.log_metadata, s.lidar, s.layout, s.log_pose_period);
  Car car{node, log.get()};
  try {
    if (s.car.clock == Clock::Lockstep) {
      run_lockstep(s, car, lidar, *can_udp, objects, out, stop);
    } else {
      run_wall(s, car, lidar, can_udp ? &*can_udp : nullptr, can_bus ? &*can_bus : nullptr, objects,
               camera ? &*camera : nullptr, out, stop);
    }
  } catch (const std::exception&) {
    // what the car logged up to the fault is the log that matters most
    if (log) log->close();
    throw;
  }
  if (log) {
    log->close();
    out << "  log      " << s.log_path << std::endl;
  }
}

}  // namespace paddock::car
