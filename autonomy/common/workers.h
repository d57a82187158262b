#pragma once
// A fixed team of threads for a loop split into parts: run(f) calls f(0) on
// the caller's thread and f(1) .. f(threads - 1) on helpers the team keeps
// (started once, asleep between runs), and returns when every part has. The
// parts must not depend on each other's order: the caller keeps the result
// deterministic (fixed parts, each writing its own outputs). One team, one
// caller at a time. A copy is a new team of as many threads (a copy of its
// owner must not share its helpers); a team of 1 starts no thread at all.
#include <cstddef>
#include <functional>
#include <memory>
#include <utility>

namespace paddock {

class Workers {
 public:
  static constexpr int kMaxThreads = 64;
  // throws std::invalid_argument outside [1, kMaxThreads]
  explicit Workers(int threads = 1);
  ~Workers();
  Workers(const Workers& o);
  Workers& operator=(const Workers& o);
  Workers(Workers&& o) noexcept;
  Workers& operator=(Workers&& o) noexcept;

  int threads() const { return threads_; }
  // f(part) for part in [0, threads()); the first exception a part throws
  // is rethrown here, after every part has returned
  void run(const std::function<void(int)>& f);

  // [begin, end) of `part` when n items are split into `parts` contiguous
  // runs as evenly as can be (the first n % parts one longer)
  static std::pair<std::size_t, std::size_t> range(std::size_t n, int parts, int part);

 private:
  struct Team;
  int threads_ = 1;
  std::unique_ptr<Team> team_;  // null for one thread
};

}  // namespace paddock
