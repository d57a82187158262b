#include "autonomy/common/workers.h"

#include <algorithm>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace paddock {

struct Workers::Team {
  std::mutex mutex;
  std::condition_variable wake, done;
  const std::function<void(int)>* job = nullptr;
  std::uint64_t generation = 0;  // one per run
  int pending = 0;               // helpers still in this run
  bool stop = false;
  std::exception_ptr error;
  std::vector<std::thread> helpers;

  explicit Team(int threads) {
    helpers.reserve(static_cast<std::size_t>(threads - 1));
    try {
      for (int part = 1; part < threads; ++part) helpers.emplace_back([this, part] { serve(part); });
    } catch (...) {
      halt();
      throw;
    }
  }
  ~Team() { halt(); }

  void halt() {
    {
      const std::lock_guard<std::mutex> lock(mutex);
      stop = true;
    }
    wake.notify_all();
    for (std::thread& t : helpers) t.join();
    helpers.clear();
  }

  void serve(int part) {
    std::uint64_t seen = 0;
    for (;;) {
      const std::function<void(int)>* f = nullptr;
      {
        std::unique_lock<std::mutex> lock(mutex);
        wake.wait(lock, [&] { return stop || generation != seen; });
        if (stop) return;
        seen = generation;
        f = job;
      }
      std::exception_ptr e;
      try {
        (*f)(part);
      } catch (...) {
        e = std::current_exception();
      }
      {
        const std::lock_guard<std::mutex> lock(mutex);
        if (e && !error) error = e;
        if (--pending == 0) done.notify_one();
      }
    }
  }
};

Workers::Workers(int threads) : threads_(threads) {
  if (threads < 1 || threads > kMaxThreads)
    throw std::invalid_argument("Workers: threads must be in [1, " + std::to_string(kMaxThreads) + "], got " +
                                std::to_string(threads));
  if (threads > 1) team_ = std::make_unique<Team>(threads);
}

Workers::~Workers() = default;

Workers::Workers(const Workers& o) : Workers(o.threads_) {}

Workers& Workers::operator=(const Workers& o) {
  if (this != &o) *this = Workers(o.threads_);
  return *this;
}

Workers::Workers(Workers&& o) noexcept : threads_(o.threads_), team_(std::move(o.team_)) { o.threads_ = 1; }

Workers& Workers::operator=(Workers&& o) noexcept {
  if (this != &o) {
    team_ = std::move(o.team_);
    threads_ = o.threads_;
    o.threads_ = 1;
  }
  return *this;
}

void Workers::run(const std::function<void(int)>& f) {
  if (!team_) {
    f(0);
    return;
  }
  Team& t = *team_;
  {
    const std::lock_guard<std::mutex> lock(t.mutex);
    t.job = &f;
    t.pending = threads_ - 1;
    t.error = nullptr;
    ++t.generation;
  }
  t.wake.notify_all();
  std::exception_ptr mine;
  try {
    f(0);
  } catch (...) {
    mine = std::current_exception();
  }
  std::exception_ptr theirs;
  {
    std::unique_lock<std::mutex> lock(t.mutex);
    t.done.wait(lock, [&t] { return t.pending == 0; });
    theirs = t.error;
    t.job = nullptr;
  }
  if (mine) std::rethrow_exception(mine);
  if (theirs) std::rethrow_exception(theirs);
}

std::pair<std::size_t, std::size_t> Workers::range(std::size_t n, int parts, int part) {
  const auto p = static_cast<std::size_t>(parts), k = static_cast<std::size_t>(part);
  const std::size_t base = n / p, extra = n % p;
  const std::size_t begin = k * base + std::min(k, extra);
  return {begin, begin + base + (k < extra ? 1 : 0)};
}

}  // namespace paddock
