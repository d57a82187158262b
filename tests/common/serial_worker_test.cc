// the serial worker: every job runs, once, in the order posted, on the
// worker's thread (or at once on the caller's without one); a queue that
// is full holds the caller back; a job that throws ends the work and its
// exception reaches the caller once
#include "autonomy/common/serial_worker.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

namespace paddock {
namespace {

TEST(SerialWorker, RunsEveryJobOnceInTheOrderPostedOnItsThread) {
  SerialWorker w(true, 2, 7);  // small batches and queue: many hand-overs, the caller held back
  ASSERT_TRUE(w.threaded());
  std::vector<int> ran;
  std::atomic<int> on_caller{0};
  const std::thread::id caller = std::this_thread::get_id();
  for (int i = 0; i < 1000; ++i) {
    w.post([&, i] {
      if (std::this_thread::get_id() == caller) ++on_caller;
      if (i % 100 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));  // the queue fills
      ran.push_back(i);
    });
    if (i % 13 == 0) w.flush();
  }
  w.drain();
  ASSERT_EQ(ran.size(), 1000u);
  for (int i = 0; i < 1000; ++i) EXPECT_EQ(ran[static_cast<std::size_t>(i)], i);
  EXPECT_EQ(on_caller.load(), 0);
}

TEST(SerialWorker, WithoutAThreadRunsEachJobAtOnce) {
  SerialWorker w(false);
  EXPECT_FALSE(w.threaded());
  int n = 0;
  w.post([&] { ++n; });
  EXPECT_EQ(n, 1);
  w.flush();
  w.drain();
  EXPECT_EQ(n, 1);
}

TEST(SerialWorker, AJobThatThrowsEndsTheWorkAndIsRethrownOnce) {
  SerialWorker w(true, 4, 3);
  std::vector<int> ran;
  int thrown = 0;
  try {  // a full batch's flush may rethrow already, or drain()
    for (int i = 0; i < 10; ++i) {
      w.post([&, i] {
        if (i == 4) throw std::runtime_error("disk full");
        ran.push_back(i);
      });
    }
    w.drain();
  } catch (const std::runtime_error& e) {
    ++thrown;
    EXPECT_STREQ(e.what(), "disk full");
  }
  EXPECT_EQ(thrown, 1);
  EXPECT_EQ(ran, (std::vector<int>{0, 1, 2, 3}));
  w.post([&] { ran.push_back(99); });  // dropped: the work has ended
  EXPECT_NO_THROW(w.drain());          // told once
  EXPECT_EQ(ran.size(), 4u);
}

TEST(SerialWorker, TheDestructorRunsWhatIsPosted) {
  std::vector<int> ran;
  {
    SerialWorker w(true);
    for (int i = 0; i < 5; ++i) w.post([&, i] { ran.push_back(i); });  // never flushed by the caller
  }
  EXPECT_EQ(ran, (std::vector<int>{0, 1, 2, 3, 4}));
}

}  // namespace
}  // namespace paddock
