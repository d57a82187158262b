#include "autonomy/stack/perception_stage.h"

#include <stdexcept>
#include <utility>

namespace paddock::stack {

namespace {
// inputs held for the next scan before they are applied without one (a
// LiDAR gone silent): some 3 s of the IMU and wheel speeds, or a few
// camera frames (1 MB each)
constexpr std::size_t kMaxQueued = 1024;
constexpr std::size_t kMaxQueuedFrames = 4;
}  // namespace

PerceptionStage::PerceptionStage(const perception::PerceptionParams& params,
                                 std::unique_ptr<perception::ConeDetector> detector)
    : params_(params),
      perception_(std::make_unique<perception::Perception>(params, std::move(detector))),
      worker_(params.threads > 1, /*max_batches=*/16, /*batch_jobs=*/1) {
  delivered_ = std::make_unique<Job>();
}

PerceptionStage::~PerceptionStage() {
  try {
    worker_.drain();
  } catch (...) {
  }
}

void PerceptionStage::apply(perception::Perception& p, Input& in) {
  if (auto* m = std::get_if<hal::Imu>(&in)) {
    p.add(*m);
  } else if (auto* w = std::get_if<hal::WheelSpeeds>(&in)) {
    p.add(*w);
  } else if (auto* e = std::get_if<hal::StateEstimate>(&in)) {
    p.add(*e);
  } else if (auto* d = std::get_if<hal::CameraDetections>(&in)) {
    p.add(std::move(*d));
  } else if (auto* f = std::get_if<hal::CameraFrame>(&in)) {
    p.add(*f);
  } else if (auto* t = std::get_if<CameraTrust>(&in)) {
    p.set_camera_distrusted(t->distrusted);
  } else if (auto* k = std::get_if<KeepPoints>(&in)) {
    p.set_keep_points(k->keep);
  }
}

void PerceptionStage::queue(Input in) {
  if (std::holds_alternative<hal::CameraFrame>(in)) ++frames_queued_;
  queued_.push_back(std::move(in));
  if (queued_.size() < kMaxQueued && frames_queued_ < kMaxQueuedFrames) return;
  // no scan comes to take them: applied now, once the jobs are done (the
  // same order, so the same state, as if the next scan's job had)
  worker_.drain();
  for (Input& i : queued_) apply(*perception_, i);
  queued_.clear();
  frames_queued_ = 0;
}

void PerceptionStage::run(perception::Perception& p, Job& job) {
  for (Input& in : job.inputs) apply(p, in);
  job.inputs.clear();
  p.process(job.scan);
  p.swap_last(job.frame);
}

const hal::LidarScan& PerceptionStage::post(hal::LidarScan scan, TimeNs now) {
  std::unique_ptr<Job> job;
  if (!spare_.empty()) {
    job = std::move(spare_.back());
    spare_.pop_back();
  } else {
    job = std::make_unique<Job>();
  }
  job->due = now + from_seconds(params_.latency);
  job->inputs.swap(queued_);
  queued_.clear();
  frames_queued_ = 0;
  job->scan = std::move(scan);
  job->done = false;
  job->error = nullptr;
  job->stepped = false;
  job->step_done = false;
  job->step_error = nullptr;
  ++posted_;
  Job* j = job.get();
  jobs_.push_back(std::move(job));
  worker_.post([this, j] {
    try {
      run(*perception_, *j);
    } catch (...) {
      j->error = std::current_exception();
    }
    tell(j->done);
  });
  worker_.flush();
  return j->scan;
}

void PerceptionStage::then(std::uint64_t job, std::function<void(const perception::PerceptionFrame&)> step) {
  const std::uint64_t first = posted_ - jobs_.size();  // the oldest job not delivered
  if (job < first || job >= posted_) throw std::logic_error("PerceptionStage::then: job not in flight");
  Job* j = jobs_[static_cast<std::size_t>(job - first)].get();
  if (j->stepped) throw std::logic_error("PerceptionStage::then: the job has its step already");
  j->stepped = true;
  worker_.post([this, j, step = std::move(step)] {
    // (a job that threw has no frame to step on: its delivery rethrows)
    if (!j->error) {
      try {
        step(j->frame);
      } catch (...) {
        j->step_error = std::current_exception();
      }
    }
    tell(j->step_done);
  });
  worker_.flush();
}

void PerceptionStage::tell(bool& flag) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    flag = true;
  }
  done_.notify_one();
}

const perception::PerceptionFrame* PerceptionStage::deliver(TimeNs now) {
  if (jobs_.empty() || jobs_.front()->due > now) return nullptr;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    Job& front = *jobs_.front();
    done_.wait(lock, [&front] { return front.done && (!front.stepped || front.step_done); });
  }
  spare_.push_back(std::move(delivered_));
  delivered_ = std::move(jobs_.front());
  jobs_.pop_front();
  if (delivered_->error) std::rethrow_exception(std::exchange(delivered_->error, nullptr));
  if (delivered_->step_error) std::rethrow_exception(std::exchange(delivered_->step_error, nullptr));
  return &delivered_->frame;
}

const perception::PerceptionFrame& PerceptionStage::last() const { return delivered_->frame; }

const perception::PerceptionStats& PerceptionStage::stats() {
  worker_.drain();
  return perception_->stats();
}

perception::Perception& PerceptionStage::perception() {
  worker_.drain();
  return *perception_;
}

}  // namespace paddock::stack
