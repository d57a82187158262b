#pragma once
// a replay's second thread (`paddock replay --threads 2`): it reads the log
// ahead of the stack and runs the perception's LiDAR pipeline on the scans
// it finds, so that the stack's thread only runs the stack.
//
// A log holds every input of a drive in advance, so the work that depends
// on the log alone can run ahead of the stack:
//   - reading: the chunks' decompression, their CRCs, the messages copied
//     out in batches (handed to the stack's thread by next());
//   - the LiDAR pipeline (motion correction, ground, clusters, filters,
//     colour): a function of the scan and the perception's odometry alone,
//     and that odometry of the IMU's and wheels' CAN frames alone (with
//     [perception.odometry] lateral_velocity off: on, it takes the stack's
//     own estimate, and nothing is computed ahead). The thread decodes the
//     packets and frames with decoders of its own, as the car's, dead-
//     reckons with an Odometry of its own, and runs the pipeline on each
//     rotation where it completes, before the batch with its last packet is
//     handed over.
// The stack's Perception asks take() for each scan (perception::LidarAhead);
// a result computed ahead is given only when its scan and odometry equal the
// stack's own, bit for bit (the pipeline keeps nothing from one scan to the
// next), else the stack runs the pipeline itself. The replay's result is
// then the same, bit for bit, with or without this thread, whatever its
// timing; what it saves shows in counters().
//
// The reader's errors (a damaged chunk) reach next() after the messages
// before them, as the reader gives them; a problem of the thread's own
// decoding only ends its computing ahead.
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <thread>
#include <vector>

#include "autonomy/hal/car_can.h"
#include "autonomy/hal/dbc.h"
#include "autonomy/hal/ouster.h"
#include "autonomy/log/mcap.h"
#include "autonomy/perception/lidar_pipeline.h"
#include "autonomy/perception/odometry.h"
#include "autonomy/perception/perception.h"

namespace paddock::car {

// what the thread computes ahead: the car's LiDAR and CAN decoders' inputs,
// and the perception whose pipeline and odometry it runs
struct AheadSetup {
  std::set<std::uint16_t> packet_channels;  // the LiDAR's UDP payloads
  std::set<std::uint16_t> can_channels;     // SocketCAN frames to the stack
  hal::ouster::SensorInfo lidar;
  hal::LidarLayout layout;
  const hal::Dbc* dbc = nullptr;  // outlives the ReadAhead
  std::string dbc_source;
  perception::PerceptionParams perception;
};

// how far the thread reads ahead
struct AheadLimits {
  // a batch is handed over at this many bytes or messages (a LiDAR
  // rotation's packets: ~400 kB), and this many wait at most: 32 MB, ~8 s
  // of a run's log; less leaves more of the pipeline to the stack, whose
  // cost varies (the first lap's mapping, the pose graph's solves), while
  // this thread's does not
  std::size_t batch_bytes = std::size_t{1} << 20;
  std::size_t batch_messages = 4096;
  std::size_t max_batches = 32;
  // scans computed ahead and not yet asked for, at most (the oldest go
  // first): more than a full queue of batches holds (~1 MB each, the scan
  // kept for the comparison)
  std::size_t max_computed = 96;
  // fewer batches than this waiting for the stack: the stack is about to
  // wait for this thread, which leaves the next scan's pipeline to it and
  // reads on (0: this thread runs every scan's)
  std::size_t leave_to_stack = 2;
};

class ReadAhead final : public perception::LidarAhead {
 public:
  struct Counters {
    std::uint64_t batches = 0;     // handed to the stack's thread
    std::uint64_t computed = 0;    // scans whose pipeline ran ahead
    std::uint64_t left = 0;        // scans left to the stack (it was close behind)
    std::uint64_t taken = 0;       // of them taken by the stack
    std::uint64_t not_ahead = 0;   // scans the stack asked for with none computed ahead
    std::uint64_t mismatched = 0;  // computed ahead on other inputs than the stack's (not taken)
    std::uint64_t dropped = 0;     // computed ahead, never asked for in time (the queue's bound)
  };

  // reads `messages` (of a reader that outlives this) on a thread of its
  // own, up to and with the first message after `until` (ns); with a setup,
  // also runs the LiDAR pipeline ahead
  ReadAhead(log::McapReader::Messages messages, std::uint64_t until, std::optional<AheadSetup> setup,
            const AheadLimits& limits = {});
  ~ReadAhead() override;
  ReadAhead(const ReadAhead&) = delete;
  ReadAhead& operator=(const ReadAhead&) = delete;

  // the next message as the reader gives it (its data valid until the next
  // call); false at the end; throws what the reader threw, where it threw it
  bool next(log::Message& out);

  std::optional<perception::LidarResult> take(const hal::LidarScan& scan,
                                              const perception::Odometry& odometry) override;

  Counters counters() const;

 private:
  // messages copied out of the reader, with their bytes
  struct Batch {
    std::vector<log::Message> messages;  // data: set when next() takes the batch
    std::vector<std::size_t> offsets;    // each message's data in bytes
    std::vector<std::uint8_t> bytes;
    bool end = false;          // the last batch
    std::exception_ptr error;  // the reader's, after the messages
  };
  // a scan's pipeline run ahead, with its inputs
  struct Computed {
    hal::LidarScan scan;
    perception::Odometry odometry;
    perception::LidarResult result;
  };
  // the thread's decoders and perception
  struct Lane {
    explicit Lane(const AheadSetup& s);
    std::set<std::uint16_t> packet_channels, can_channels;
    hal::ouster::Decoder lidar;
    hal::CarCan can;
    perception::Odometry odometry;
    perception::LidarPipeline pipeline;
  };

  void run();
  // the lane's share of one message (before its batch is handed over)
  void compute(const log::Message& m);
  void hand_over(Batch& b);  // waits while the queue is full (or until stopped)

  log::McapReader::Messages messages_;
  std::uint64_t until_;
  AheadLimits limits_;
  std::unique_ptr<Lane> lane_;

  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Batch> batches_;  // read, not yet taken by next()
  std::deque<Computed> computed_;
  std::vector<Batch> spare_;   // taken batches' storage, for reuse
  std::atomic<bool> stop_{false};  // set under the mutex
  Counters counters_;

  Batch current_;        // next()'s batch
  std::size_t cursor_ = 0;
  bool ended_ = false;
  std::thread thread_;  // last: starts once the rest is built
};

}  // namespace paddock::car
