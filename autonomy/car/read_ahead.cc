#include "autonomy/car/read_ahead.h"

#include <algorithm>
#include <utility>
#include <variant>

#include "autonomy/common/same_bits.h"

namespace paddock::car {

namespace {

// the same rotation, bit for bit
bool same_scan(const hal::LidarScan& a, const hal::LidarScan& b) {
  if (a.stamp != b.stamp || a.end != b.end || a.points.size() != b.points.size()) return false;
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    const hal::LidarPoint& p = a.points[i];
    const hal::LidarPoint& q = b.points[i];
    if (p.t != q.t || p.ring != q.ring || !same_bits(p.x, q.x) || !same_bits(p.y, q.y) || !same_bits(p.z, q.z) ||
        !same_bits(p.intensity, q.intensity))
      return false;
  }
  return true;
}

}  // namespace

ReadAhead::Lane::Lane(const AheadSetup& s)
    : packet_channels(s.packet_channels),
      can_channels(s.can_channels),
      lidar(s.lidar, s.layout),
      can(*s.dbc, s.dbc_source),
      odometry(s.perception.odometry),
      pipeline(s.perception.lidar) {}

ReadAhead::ReadAhead(log::McapReader::Messages messages, std::uint64_t until, std::optional<AheadSetup> setup,
                     const AheadLimits& limits)
    : messages_(std::move(messages)), until_(until), limits_(limits) {
  limits_.max_batches = std::max<std::size_t>(limits_.max_batches, 1);
  // (lateral_velocity: the odometry takes the stack's estimate, which no log holds)
  if (setup && setup->dbc && !setup->perception.odometry.lateral_velocity) lane_ = std::make_unique<Lane>(*setup);
  thread_ = std::thread([this] { run(); });
}

ReadAhead::~ReadAhead() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

void ReadAhead::hand_over(Batch& b) {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [this] { return stop_ || batches_.size() < limits_.max_batches; });
  if (stop_) return;
  batches_.push_back(std::move(b));
  ++counters_.batches;
  // the next batch in storage that has held one before
  b = Batch{};
  if (!spare_.empty()) {
    b = std::move(spare_.back());
    spare_.pop_back();
  }
  b.messages.clear();
  b.offsets.clear();
  b.bytes.clear();
  b.end = false;
  b.error = nullptr;
  lock.unlock();
  changed_.notify_all();
}

void ReadAhead::run() {
  Batch b;
  try {
    log::Message m;
    for (;;) {
      if (stop_) return;
      if (!messages_.next(m)) break;
      b.messages.push_back(m);
      b.offsets.push_back(b.bytes.size());
      b.bytes.insert(b.bytes.end(), m.data, m.data + m.size);
      if (lane_) compute(m);
      if (m.log_time > until_) break;  // the stack stops at it
      if (b.bytes.size() >= limits_.batch_bytes || b.messages.size() >= limits_.batch_messages) hand_over(b);
    }
  } catch (...) {
    b.error = std::current_exception();
  }
  b.end = true;
  hand_over(b);
}

void ReadAhead::compute(const log::Message& m) {
  Lane& l = *lane_;
  try {
    if (l.can_channels.count(m.channel_id)) {
      if (const std::optional<hal::CanFrame> f =
              hal::from_socketcan(m.data, m.size, static_cast<TimeNs>(m.log_time))) {
        l.can.push(*f);
        while (std::optional<hal::SensorMessage> s = l.can.pop_sensor()) {
          if (const auto* imu = std::get_if<hal::Imu>(&*s)) l.odometry.add(*imu);
          else if (const auto* wheels = std::get_if<hal::WheelSpeeds>(&*s)) l.odometry.add(*wheels);
        }
      }
    } else if (l.packet_channels.count(m.channel_id)) {
      l.lidar.push(m.data, m.size);
      while (std::optional<hal::LidarScan> scan = l.lidar.pop()) {
        {
          // the stack close behind (its thread waits for messages, not
          // this one for room): it runs this scan's pipeline itself, and
          // this thread reads on
          const std::lock_guard<std::mutex> lock(mutex_);
          if (batches_.size() < limits_.leave_to_stack) {
            ++counters_.left;
            continue;
          }
        }
        Computed c{std::move(*scan), l.odometry, {}};
        c.result = l.pipeline.process(c.scan, &c.odometry);
        const std::lock_guard<std::mutex> lock(mutex_);
        computed_.push_back(std::move(c));
        ++counters_.computed;
        while (computed_.size() > limits_.max_computed) {
          computed_.pop_front();
          ++counters_.dropped;
        }
      }
    }
  } catch (...) {
    // the stack's own thread computes what this one cannot
    lane_.reset();
  }
}

bool ReadAhead::next(log::Message& out) {
  while (cursor_ >= current_.messages.size()) {
    if (ended_) {
      if (current_.error) {
        const std::exception_ptr e = current_.error;
        current_.error = nullptr;
        std::rethrow_exception(e);
      }
      return false;
    }
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [this] { return !batches_.empty(); });
    spare_.push_back(std::move(current_));
    current_ = std::move(batches_.front());
    batches_.pop_front();
    lock.unlock();
    changed_.notify_all();
    cursor_ = 0;
    ended_ = current_.end;
    for (std::size_t i = 0; i < current_.messages.size(); ++i)
      current_.messages[i].data = current_.bytes.data() + current_.offsets[i];
  }
  out = current_.messages[cursor_++];
  return true;
}

std::optional<perception::LidarResult> ReadAhead::take(const hal::LidarScan& scan,
                                                       const perception::Odometry& odometry) {
  std::unique_lock<std::mutex> lock(mutex_);
  // (a scan's pipeline runs ahead before the batch with its last packet is
  // handed over: one the stack has is computed by now, or will never be)
  while (!computed_.empty() && computed_.front().scan.end < scan.end) {
    computed_.pop_front();
    ++counters_.dropped;
  }
  if (computed_.empty() || computed_.front().scan.end != scan.end) {
    ++counters_.not_ahead;
    return std::nullopt;
  }
  Computed c = std::move(computed_.front());
  computed_.pop_front();
  lock.unlock();
  const bool same = same_scan(c.scan, scan) && c.odometry.same_state(odometry);
  lock.lock();
  if (!same) {
    ++counters_.mismatched;
    return std::nullopt;
  }
  ++counters_.taken;
  return std::move(c.result);
}

ReadAhead::Counters ReadAhead::counters() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return counters_;
}

}  // namespace paddock::car
