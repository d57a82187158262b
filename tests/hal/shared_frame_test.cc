// a frame lent without a copy (hal/shared_frame.h): the writer gets its own
// frame back once no lease is out, a new one while one is, and a reader's
// frame never changes under it, with the reader on another thread too
#include "autonomy/hal/shared_frame.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <thread>
#include <vector>

namespace paddock::hal {
namespace {

void paint(CameraFrame& f, std::uint8_t v, TimeNs stamp) {
  f.stamp = stamp;
  f.width = 4;
  f.height = 2;
  f.rgb.assign(24, v);
}

TEST(SharedFrame, TheWriterGetsItsFrameBackOnceNoLeaseIsOut) {
  std::shared_ptr<SharedFrame> owned;
  SharedFrame& first = writable(owned);
  paint(first.frame, 1, 10);
  EXPECT_EQ(&writable(owned), &first);  // no lease: the same frame
  {
    const FrameLease lease(owned);
    EXPECT_TRUE(lent(*owned));
    FrameLease copy = lease;  // a second reader
    // a lease out: the writer paints a new frame, the readers keep theirs
    SharedFrame& second = writable(owned);
    EXPECT_NE(&second, &first);
    paint(second.frame, 2, 20);
    EXPECT_EQ(lease->stamp, 10);
    EXPECT_EQ(copy->rgb, std::vector<std::uint8_t>(24, 1));
    EXPECT_FALSE(lent(second));
    FrameLease moved = std::move(copy);
    EXPECT_EQ((*moved).stamp, 10);
  }
  // every lease let go: the frame is the writer's again
  EXPECT_FALSE(lent(*owned));
  EXPECT_EQ(writable(owned).frame.stamp, 20);
}

TEST(SharedFrame, AReaderOnAnotherThreadSeesItsFrameWhole) {
  // the writer paints frame after frame, lending each to a reader thread
  // that checks every pixel is its frame's; the writer never waits (TSan:
  // no race)
  std::shared_ptr<SharedFrame> owned;
  std::vector<std::thread> readers;
  std::vector<int> bad(50, 0);
  for (int k = 0; k < 50; ++k) {
    SharedFrame& f = writable(owned);
    paint(f.frame, static_cast<std::uint8_t>(k), k);
    readers.emplace_back([lease = FrameLease(owned), k, &bad] {
      for (int pass = 0; pass < 100; ++pass)
        for (std::uint8_t v : lease->rgb) bad[static_cast<std::size_t>(k)] += v != k ? 1 : 0;
    });
  }
  for (std::thread& t : readers) t.join();
  for (int k = 0; k < 50; ++k) EXPECT_EQ(bad[static_cast<std::size_t>(k)], 0) << k;
  EXPECT_FALSE(lent(*owned));
}

}  // namespace
}  // namespace paddock::hal
