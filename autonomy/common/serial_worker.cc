#include "autonomy/common/serial_worker.h"

#include <utility>

namespace paddock {

SerialWorker::SerialWorker(bool threaded, std::size_t max_batches, std::size_t batch_jobs)
    : max_batches_(max_batches < 1 ? 1 : max_batches), batch_jobs_(batch_jobs < 1 ? 1 : batch_jobs) {
  if (threaded) thread_ = std::thread([this] { loop(); });
}

SerialWorker::~SerialWorker() {
  try {
    flush();
  } catch (...) {
  }
  if (!thread_.joinable()) return;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_one();
  thread_.join();
}

void SerialWorker::rethrow() {
  if (!error_) return;
  std::exception_ptr e = std::exchange(error_, nullptr);
  std::rethrow_exception(e);
}

void SerialWorker::post(Job job) {
  if (!threaded()) {
    job();
    return;
  }
  batch_.push_back(std::move(job));
  if (batch_.size() >= batch_jobs_) flush();
}

void SerialWorker::flush() {
  if (!threaded()) return;
  std::unique_lock<std::mutex> lock(mutex_);
  rethrow();
  if (batch_.empty()) return;
  room_.wait(lock, [&] { return queue_.size() < max_batches_; });
  queue_.push_back(std::move(batch_));
  batch_.clear();
  lock.unlock();
  wake_.notify_one();
}

void SerialWorker::drain() {
  flush();
  if (!threaded()) return;
  std::unique_lock<std::mutex> lock(mutex_);
  room_.wait(lock, [&] { return queue_.empty() && !running_; });
  rethrow();
}

void SerialWorker::loop() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_.wait(lock, [&] { return stop_ || !queue_.empty(); });
    if (queue_.empty()) return;  // stopped, and nothing left
    std::vector<Job> jobs = std::move(queue_.front());
    queue_.pop_front();
    running_ = true;
    const bool failed = failed_;
    lock.unlock();
    room_.notify_one();
    std::exception_ptr error;
    if (!failed) {
      for (Job& job : jobs) {
        try {
          job();
        } catch (...) {
          error = std::current_exception();
          break;
        }
      }
    }
    jobs.clear();  // the jobs' captures freed here, off the caller's thread
    lock.lock();
    running_ = false;
    if (error && !failed_) failed_ = true, error_ = error;
    room_.notify_one();
  }
}

}  // namespace paddock
