// the profile's accounting on a clock the test moves: exclusive time per
// stage, nesting, and the time inside no stage
#include "autonomy/common/profile.h"

#include <gtest/gtest.h>

#include <thread>

namespace paddock {
namespace {

Profile::Clock::time_point fake_now;
Profile::Clock::time_point read_fake() { return fake_now; }
void at(double seconds) {
  fake_now = Profile::Clock::time_point(std::chrono::duration_cast<Profile::Clock::duration>(std::chrono::duration<double>(seconds)));
}

TEST(Profile, StagesAreChargedTheirOwnTimeAndAddUpToTheWhole) {
  at(100.0);
  Profile p(&read_fake);
  p.enter(Stage::Physics);  // before start: counted, not timed
  at(101.0);
  p.leave();
  p.start();
  at(102.0);  // 1 s in no stage
  p.enter(Stage::Perception);
  at(104.0);  // 2 s perception
  {
    const StageScope inner(&p, Stage::Localisation);
    at(107.0);  // 3 s localisation, inside perception: not perception's
    const StageScope deeper(&p, Stage::Localisation);
    at(107.5);
  }
  at(108.0);  // 0.5 s more perception (the scopes closed at 107.5)
  p.leave();
  p.leave();  // one leave too many: ignored
  at(108.25);
  p.stop();
  at(200.0);  // after stop: nothing
  EXPECT_DOUBLE_EQ(p.seconds(Stage::Other), 1.25);
  EXPECT_DOUBLE_EQ(p.seconds(Stage::Perception), 2.5);
  EXPECT_DOUBLE_EQ(p.seconds(Stage::Localisation), 3.5);
  EXPECT_DOUBLE_EQ(p.seconds(Stage::Physics), 0.0);
  EXPECT_EQ(p.entries(Stage::Physics), 1u);
  EXPECT_EQ(p.entries(Stage::Localisation), 2u);
  EXPECT_DOUBLE_EQ(p.total(), 108.25 - 101.0);
  const StageScope nothing(nullptr, Stage::Control);  // no profile: nothing timed, no crash
}

TEST(Profile, ScopesDeeperThanItsStackAreChargedToTheDeepestItHolds) {
  at(0.0);
  Profile p(&read_fake);
  p.start();
  p.enter(Stage::Physics);
  for (int i = 0; i < 20; ++i) p.enter(i < 15 ? Stage::Physics : Stage::Control);  // 21 open, 16 held
  at(1.0);
  for (int i = 0; i < 20; ++i) p.leave();
  at(3.0);
  p.leave();
  p.stop();
  EXPECT_DOUBLE_EQ(p.seconds(Stage::Physics), 3.0);
  EXPECT_DOUBLE_EQ(p.seconds(Stage::Control), 0.0);
  EXPECT_EQ(p.entries(Stage::Control), 5u);
  EXPECT_EQ(stage_name(Stage::Localisation), "localisation");
}

// the CPU's counter, its rate measured against steady_clock: a stage's
// time is what steady_clock saw pass in it, and the whole is the time
// from start() to stop() by steady_clock
TEST(Profile, TheCpusCounterGivesSteadyClocksSeconds) {
  using Clock = Profile::Clock;
  const auto seconds = [](Clock::time_point from, Clock::time_point to) {
    return std::chrono::duration<double>(to - from).count();
  };
  Profile p;
  const Clock::time_point t0 = Clock::now();
  p.start();
  p.enter(Stage::Camera);
  const Clock::time_point c0 = Clock::now();
  std::this_thread::sleep_for(std::chrono::milliseconds(30));
  const Clock::time_point c1 = Clock::now();
  p.leave();
  p.stop();
  const Clock::time_point t1 = Clock::now();
  EXPECT_NEAR(p.seconds(Stage::Camera), seconds(c0, c1), 0.005);
  EXPECT_GE(p.total(), seconds(c0, c1) - 1e-6);
  EXPECT_LE(p.total(), seconds(t0, t1) + 1e-6);
  EXPECT_LT(p.seconds(Stage::Other), 0.005);
}

std::uint64_t fake_allocations = 0;
std::uint64_t read_allocations() { return fake_allocations; }

TEST(Profile, StagesAreChargedTheAllocationsMadeInsideThem) {
  at(0.0);
  fake_allocations = 1000;
  Profile untimed(&read_fake);
  EXPECT_FALSE(untimed.counts_allocations());
  Profile p(&read_fake, &read_allocations);
  EXPECT_TRUE(p.counts_allocations());
  p.enter(Stage::Camera);
  fake_allocations += 50;  // before start: not counted
  p.leave();
  p.start();
  fake_allocations += 3;  // other
  {
    const StageScope camera(&p, Stage::Camera);
    fake_allocations += 7;
    {
      const StageScope slam(&p, Stage::Localisation);
      fake_allocations += 11;  // localisation's, not the camera's
    }
    fake_allocations += 2;
  }
  p.stop();
  fake_allocations += 100;  // after stop: nothing
  EXPECT_EQ(p.allocations(Stage::Other), 3u);
  EXPECT_EQ(p.allocations(Stage::Camera), 9u);
  EXPECT_EQ(p.allocations(Stage::Localisation), 11u);
  EXPECT_EQ(p.allocations(Stage::Physics), 0u);
  EXPECT_EQ(p.total_allocations(), 23u);
  EXPECT_EQ(untimed.total_allocations(), 0u);
}

}  // namespace
}  // namespace paddock
