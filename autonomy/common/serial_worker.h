#pragma once
// A thread that runs the jobs posted to it one after another, in the order
// they were posted: work whose result is the same whichever thread does it
// (a log's encoding, compression and writing) taken off a loop that must
// not wait for it. Jobs are handed over in batches (flush(), or a full
// batch), so the threads meet once a batch, not once a job. At most
// max_batches batches wait: a caller that posts faster than the thread runs
// waits (flush) instead of holding ever more memory.
//
// A job that throws ends the work: the jobs after it are dropped, and the
// exception is rethrown (once) on the caller's thread by the next flush()
// or drain(); later jobs are dropped as well. Without a thread (threaded = false) post() runs each job at
// once, on the caller's thread: the same jobs in the same order.
//
// One caller thread at a time (post, flush and drain are not for two).
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace paddock {

class SerialWorker {
 public:
  using Job = std::function<void()>;

  explicit SerialWorker(bool threaded = true, std::size_t max_batches = 16, std::size_t batch_jobs = 256);
  // drains what is posted (an exception a job throws is lost: drain() first to see it)
  ~SerialWorker();
  SerialWorker(const SerialWorker&) = delete;
  SerialWorker& operator=(const SerialWorker&) = delete;

  bool threaded() const { return thread_.joinable(); }
  // the job after every job posted before it; a full batch is flushed
  void post(Job job);
  // hands the batch to the thread (waits while max_batches are waiting)
  void flush();
  // returns when every job posted has run; rethrows what a job threw
  void drain();

 private:
  void loop();
  void rethrow();  // the first exception a job threw (once)

  std::size_t max_batches_, batch_jobs_;
  std::vector<Job> batch_;  // the caller's, not yet handed over
  std::mutex mutex_;
  std::condition_variable wake_;  // the thread: a batch or the end
  std::condition_variable room_;  // the caller: room in the queue, or the work done
  std::deque<std::vector<Job>> queue_;
  bool running_ = false;  // the thread is inside a batch
  bool stop_ = false;
  bool failed_ = false;         // a job threw: no job runs again
  std::exception_ptr error_;    // what it threw, until rethrown
  std::thread thread_;
};

}  // namespace paddock
