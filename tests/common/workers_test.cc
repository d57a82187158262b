// the thread team: every part run once per run, on as many threads; the
// split of n items covers each once; a part's exception reaches the caller
// after every part has returned; a copy is a team of its own
#include "autonomy/common/workers.h"

#include <atomic>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

namespace paddock {
namespace {

TEST(Workers, EveryPartRunsOncePerRunOnItsOwnThread) {
  for (int threads : {1, 2, 5}) {
    Workers w(threads);
    EXPECT_EQ(w.threads(), threads);
    for (int run = 0; run < 50; ++run) {
      std::vector<int> calls(static_cast<std::size_t>(threads), 0);
      std::vector<std::thread::id> ids(static_cast<std::size_t>(threads));
      w.run([&](int part) {
        ++calls[static_cast<std::size_t>(part)];
        ids[static_cast<std::size_t>(part)] = std::this_thread::get_id();
      });
      for (int c : calls) EXPECT_EQ(c, 1);
      EXPECT_EQ(ids[0], std::this_thread::get_id());  // part 0: the caller
      EXPECT_EQ(std::set<std::thread::id>(ids.begin(), ids.end()).size(), static_cast<std::size_t>(threads));
    }
  }
  EXPECT_THROW(Workers(0), std::invalid_argument);
  EXPECT_THROW(Workers(Workers::kMaxThreads + 1), std::invalid_argument);
}

TEST(Workers, RangesSplitTheItemsIntoContiguousRunsAsEvenlyAsCanBe) {
  for (std::size_t n : {0u, 1u, 7u, 200u, 201u}) {
    for (int parts : {1, 2, 3, 8}) {
      std::size_t next = 0, lo = n, hi = 0;
      for (int part = 0; part < parts; ++part) {
        const auto [b, e] = Workers::range(n, parts, part);
        EXPECT_EQ(b, next);  // contiguous, in order
        lo = std::min(lo, e - b);
        hi = std::max(hi, e - b);
        next = e;
      }
      EXPECT_EQ(next, n);
      EXPECT_LE(hi - std::min(lo, hi), 1u);
    }
  }
}

TEST(Workers, APartsExceptionReachesTheCallerAfterEveryPartReturned) {
  Workers w(3);
  std::atomic<int> finished{0};
  EXPECT_THROW(w.run([&](int part) {
                 if (part == 2) throw std::runtime_error("part 2");
                 std::this_thread::sleep_for(std::chrono::milliseconds(20));
                 ++finished;
               }),
               std::runtime_error);
  EXPECT_EQ(finished.load(), 2);
  // the team still works
  std::atomic<int> sum{0};
  w.run([&](int part) { sum += part; });
  EXPECT_EQ(sum.load(), 0 + 1 + 2);
  // a copy has threads of its own, and both run
  Workers c = w;
  EXPECT_EQ(c.threads(), 3);
  sum = 0;
  c.run([&](int part) { sum += part; });
  w.run([&](int part) { sum += part; });
  EXPECT_EQ(sum.load(), 6);
}

}  // namespace
}  // namespace paddock
