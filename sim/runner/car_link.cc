#include "sim/runner/car_link.h"

#include <cstdio>
#include <stdexcept>

namespace paddock::runner {

CarLink::CarLink(const car::CarParams& car)
    : car_(car),
      socket_("0.0.0.0", 0),  // any interface: the car binary may be on another machine
      lidar_(hal::UdpSocket::address(car.host, car.lidar_port)),
      can_(hal::UdpSocket::address(car.host, car.can_port)),
      objects_(hal::UdpSocket::address(car.host, car.objects_port)) {}

CarLink::~CarLink() {
  try {
    hal::CanDatagram d;
    d.kind = hal::CanDatagram::Kind::End;
    send(d);
  } catch (const std::exception&) {
    // the car binary is gone already: nothing to tell it
  }
}

void CarLink::send(hal::CanDatagram& d) {
  d.sequence = sequence_++;
  d.lidar_before = lidar_sent_;
  d.objects_before = objects_sent_;
  const std::vector<std::uint8_t> bytes = hal::encode(d);
  socket_.send_to(can_, bytes.data(), bytes.size());
}

hal::CanDatagram CarLink::await(hal::CanDatagram::Kind kind, TimeNs now) {
  char at[64];
  std::snprintf(at, sizeof at, " at t = %.3f s", to_seconds(now));
  const std::string who = "the car binary (" + car_.host + ":" + std::to_string(car_.can_port) + ")";
  if (!socket_.receive(buf_, from_seconds(car_.peer_timeout)))
    throw std::runtime_error(who + " gave no " + hal::to_string(kind) + at + " within " +
                             std::to_string(car_.peer_timeout) + " s ([car] peer_timeout): is `paddock car` running?");
  std::string why;
  const std::optional<hal::CanDatagram> d = hal::decode_datagram(buf_.data(), buf_.size(), &why);
  if (!d) throw std::runtime_error(who + " answered" + at + " with no CAN-over-UDP datagram: " + why);
  if (d->sequence != answers_ || d->time != now || d->kind != kind)
    throw std::runtime_error(who + " answered out of turn" + at + ": " + hal::to_string(d->kind) + " " +
                             std::to_string(d->sequence) + " where " + hal::to_string(kind) + " " +
                             std::to_string(answers_) + " was due");
  ++answers_;
  return *d;
}

void CarLink::lidar_packet(TimeNs now, const std::uint8_t* data, std::size_t size) {
  socket_.send_to(lidar_, data, size);
  ++lidar_sent_;
  if (++lidar_unsynced_ < kSyncEvery) return;
  hal::CanDatagram d;
  d.kind = hal::CanDatagram::Kind::Sync;
  d.time = now;
  send(d);
  await(hal::CanDatagram::Kind::Ack, now);
  lidar_unsynced_ = 0;
}

void CarLink::can_frames(TimeNs now, const std::vector<hal::CanFrame>& frames) {
  hal::CanDatagram d;
  d.time = now;
  d.frames = frames;
  send(d);
}

void CarLink::object(TimeNs, const std::string& json) {
  socket_.send_to(objects_, reinterpret_cast<const std::uint8_t*>(json.data()), json.size());
  ++objects_sent_;
}

std::vector<hal::CanFrame> CarLink::tick(TimeNs now) {
  hal::CanDatagram d;
  d.kind = hal::CanDatagram::Kind::Tick;
  d.time = now;
  send(d);
  lidar_unsynced_ = 0;  // the car takes every packet before it runs the cycle
  return await(hal::CanDatagram::Kind::Reply, now).frames;
}

}  // namespace paddock::runner
