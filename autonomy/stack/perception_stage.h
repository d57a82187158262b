#pragma once
// the perception front as the stack runs it (perception = lidar |
// lidar_camera): its inputs taken in the order they come, each LiDAR scan
// processed as a job, and the scan's cones delivered [perception] latency
// after the scan came.
//
// The latency is the pipeline's compute on the car (the paper's runs on a
// computer of its own; the ground-truth cone sensor's frames come 0.1 s
// late, [cone_sensor] latency): the localisation takes the cones, stamped at
// the rotation's end, that much later, as on the car. 0: at once, within the
// message that brought the scan.
//
// A job is the scan and every input that came since the last scan (the
// odometry's samples, state estimates, the camera's detections or frames,
// the camera's trust, keep_points), applied to the one Perception in their
// order, then the scan processed. The jobs run in the order posted: with
// [perception] threads = 2 on a thread of their own (a SerialWorker) while
// the stack goes on, else at once on the caller's. Nothing but the jobs
// touches the Perception between a post and the delivery, and a job owns
// its inputs: so the frames are the same, bit for bit, on one thread or two,
// whatever the timing. The caller waits for the jobs only when a frame is
// due (with a latency of a rotation or more the thread works beside the
// next rotation's simulation and the stack's mapping of the last frame).
// A caller's step on a job's frame (then(): the stack's SLAM update of it)
// runs on the same thread after the job, and the frame's delivery waits
// for it too.
//
// One caller thread (the stack's). No I/O, no clock.
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <variant>
#include <vector>

#include "autonomy/common/serial_worker.h"
#include "autonomy/common/time.h"
#include "autonomy/hal/messages.h"
#include "autonomy/perception/perception.h"

namespace paddock::stack {

class PerceptionStage {
 public:
  // throws std::invalid_argument when the params are invalid (Perception's)
  PerceptionStage(const perception::PerceptionParams& params, std::unique_ptr<perception::ConeDetector> detector);
  // waits for the jobs
  ~PerceptionStage();
  PerceptionStage(const PerceptionStage&) = delete;
  PerceptionStage& operator=(const PerceptionStage&) = delete;

  // inputs, for the next scan's job (in this order)
  void add(const hal::Imu& m) { queue(m); }
  void add(const hal::WheelSpeeds& m) { queue(m); }
  // (taken only for the odometry's lateral velocity: else it ignores them)
  void add(const hal::StateEstimate& m) {
    if (params_.odometry.lateral_velocity) queue(m);
  }
  void add(hal::CameraDetections m) { queue(std::move(m)); }
  void add(hal::CameraFrame m) { queue(std::move(m)); }
  // Perception::set_camera_distrusted and set_keep_points, from the next scan on
  void set_camera_distrusted(bool d) {
    if (d != camera_distrusted_) queue(CameraTrust{d});
    camera_distrusted_ = d;
  }
  void set_keep_points(bool keep) { queue(KeepPoints{keep}); }

  // the scan's job, its frame due at now + latency. Returns the scan as the
  // job holds it, to be read (not written) until the frame is delivered
  const hal::LidarScan& post(hal::LidarScan scan, TimeNs now);
  // the number of the job post() made last (the first is 0)
  std::uint64_t last_posted() const { return posted_ - 1; }
  // a step of the caller's on job `job`'s frame, run on the jobs' thread
  // after the job (and the jobs before it), before the frame is delivered:
  // deliver() waits for it, and rethrows what it threw. One a job, for a
  // job posted and not delivered yet (else std::logic_error); the step must
  // touch nothing the caller reads until the frame is delivered
  void then(std::uint64_t job, std::function<void(const perception::PerceptionFrame&)> step);
  // whether the jobs run on a thread of their own ([perception] threads = 2)
  bool threaded() const { return worker_.threaded(); }
  // the oldest frame due at or before now, once its job has run (waited
  // for; the jobs posted after it run on); null when none is due. Valid
  // until the next call. What the job threw is thrown here
  const perception::PerceptionFrame* deliver(TimeNs now);
  // the frame delivered last (an empty one before the first)
  const perception::PerceptionFrame& last() const;
  // frames posted and not delivered yet
  std::size_t in_flight() const { return jobs_.size(); }

  // every job run: the perception's counters, and the Perception itself
  // (its params; the replay's set_ahead before and after a run)
  const perception::PerceptionStats& stats();
  perception::Perception& perception();
  const perception::PerceptionParams& params() const { return params_; }

 private:
  struct CameraTrust {
    bool distrusted;
  };
  struct KeepPoints {
    bool keep;
  };
  using Input = std::variant<hal::Imu, hal::WheelSpeeds, hal::StateEstimate, hal::CameraDetections, hal::CameraFrame,
                             CameraTrust, KeepPoints>;
  struct Job {
    TimeNs due = 0;
    std::vector<Input> inputs;
    hal::LidarScan scan;
    perception::PerceptionFrame frame;
    bool done = false;           // under mutex_
    std::exception_ptr error;    // what the job threw, rethrown at its delivery
    bool stepped = false;        // a step follows it (then)
    bool step_done = false;      // under mutex_
    std::exception_ptr step_error;  // what the step threw
  };
  void queue(Input in);
  static void apply(perception::Perception& p, Input& in);
  // runs on the worker (or at once): the inputs applied, then the scan
  static void run(perception::Perception& p, Job& job);
  // on the worker: a job's (or its step's) end, told to the caller waiting for it
  void tell(bool& flag);

  perception::PerceptionParams params_;
  std::unique_ptr<perception::Perception> perception_;
  std::vector<Input> queued_;
  std::size_t frames_queued_ = 0;  // camera frames among them
  bool camera_distrusted_ = false;  // as last queued
  // posted, oldest first
  std::deque<std::unique_ptr<Job>> jobs_;
  std::vector<std::unique_ptr<Job>> spare_;
  std::uint64_t posted_ = 0;  // jobs posted
  std::unique_ptr<Job> delivered_;
  // a job's end, told to the caller waiting for its frame
  std::mutex mutex_;
  std::condition_variable done_;
  // last: it runs the jobs, and is drained first when destroyed
  SerialWorker worker_;
};

}  // namespace paddock::stack
