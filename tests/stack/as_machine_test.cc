// the rules' AS state machine on its own: every transition of the FS rules'
// state diagram, each condition of AS Ready, the 5 s in AS Ready before a go
// counts, and the reason kept with each transition
#include "autonomy/stack/as_machine.h"

#include <gtest/gtest.h>

#include <string>

namespace paddock::stack {
namespace {

using hal::AsState;

constexpr TimeNs kMs = 1'000'000;

// a car whose every check passes: ASMS on, the mission selected, the EBS armed
// (10 bar), the brakes closed (100 bar), the stack ready
AsInputs ready_car() {
  AsInputs in;
  in.vcu_known = true;
  in.asms_on = true;
  in.mission_selected = true;
  in.ebs_pressure = 10.0;
  in.brake_pressure = 100.0;
  in.stack_ready = true;
  return in;
}

AsInputs with_go(AsInputs in) {
  in.go = true;
  return in;
}

TEST(AsMachine, ReadyNeedsEveryCheckAndSaysWhichFails) {
  struct Case {
    const char* name;
    void (*spoil)(AsInputs&);
    const char* waiting;
  };
  const Case cases[] = {
      {"no VCU", [](AsInputs& in) { in.vcu_known = false; }, "no VCU status"},
      {"ASMS off", [](AsInputs& in) { in.asms_on = false; }, "ASMS off"},
      {"other mission", [](AsInputs& in) { in.mission_selected = false; }, "selected mission"},
      {"EBS empty", [](AsInputs& in) { in.ebs_pressure = 5.9; }, "EBS not armed (tank 5.9 bar, needs 6.0 bar)"},
      {"brakes open", [](AsInputs& in) { in.brake_pressure = 4.0; }, "brakes not closed"},
      {"fault", [](AsInputs& in) { in.fault = "watchdog: no LiDAR"; }, "watchdog: no LiDAR"},
      {"RES", [](AsInputs& in) { in.res_emergency = true; }, "RES emergency"},
      {"no plan", [](AsInputs& in) { in.stack_ready = false; }, "no state estimate or trajectory"},
  };
  for (const Case& c : cases) {
    AsMachine m{AsParams{}};
    AsInputs in = ready_car();
    c.spoil(in);
    for (TimeNs t = 0; t < 1000 * kMs; t += 10 * kMs) EXPECT_EQ(m.update(t, in), AsState::Off) << c.name;
    EXPECT_NE(m.waiting_for().find(c.waiting), std::string::npos) << c.name << ": " << m.waiting_for();
    EXPECT_TRUE(m.transitions().empty()) << c.name;
    // mended, it goes to Ready
    EXPECT_EQ(m.update(1000 * kMs, ready_car()), AsState::Ready) << c.name;
    EXPECT_TRUE(m.waiting_for().empty());
  }
}

TEST(AsMachine, TheGoCountsOnlyAfterFiveSecondsInReady) {
  AsMachine m{AsParams{}};
  EXPECT_EQ(m.update(100 * kMs, ready_car()), AsState::Ready);
  // 4.99 s in Ready: ignored (and said so); the go is a button press, not latched
  EXPECT_EQ(m.update(5090 * kMs, with_go(ready_car())), AsState::Ready);
  EXPECT_NE(m.ignored_go().find("4.990 s in AS Ready"), std::string::npos) << m.ignored_go();
  EXPECT_EQ(m.update(5100 * kMs, ready_car()), AsState::Ready);
  // 5 s exactly: taken
  EXPECT_EQ(m.update(5100 * kMs, with_go(ready_car())), AsState::Driving);
  ASSERT_EQ(m.transitions().size(), 2u);
  EXPECT_EQ(m.transitions()[1].from, AsState::Ready);
  EXPECT_EQ(m.transitions()[1].to, AsState::Driving);
  EXPECT_EQ(m.transitions()[1].t, 5100 * kMs);
}

// drives a fresh machine to Driving (no ready wait)
AsMachine driving() {
  AsParams p;
  p.ready_wait = 0.0;
  AsMachine m{p};
  EXPECT_EQ(m.update(0, with_go(ready_car())), AsState::Driving);
  return m;
}

TEST(AsMachine, EmergencyFromReadyAndDrivingOnEachCause) {
  struct Case {
    const char* name;
    void (*spoil)(AsInputs&);
    const char* reason;
  };
  const Case cases[] = {
      {"RES", [](AsInputs& in) { in.res_emergency = true; }, "RES emergency stop"},
      {"fault", [](AsInputs& in) { in.fault = "stack cycle overrun"; }, "stack cycle overrun"},
      {"EBS lost", [](AsInputs& in) { in.ebs_pressure = 2.0; }, "EBS disarmed: tank 2.0 bar below 6.0 bar"},
  };
  for (const Case& c : cases) {
    for (const bool from_driving : {false, true}) {
      AsParams p;
      p.ready_wait = 0.0;
      AsMachine m{p};
      m.update(0, from_driving ? with_go(ready_car()) : ready_car());
      ASSERT_EQ(m.state(), from_driving ? AsState::Driving : AsState::Ready);
      AsInputs in = ready_car();
      c.spoil(in);
      EXPECT_EQ(m.update(10 * kMs, in), AsState::Emergency) << c.name;
      EXPECT_EQ(m.transitions().back().reason, c.reason);
      // latched: the cause going away does not end it
      EXPECT_EQ(m.update(20 * kMs, ready_car()), AsState::Emergency) << c.name;
      // only the ASMS switched off does
      AsInputs off = ready_car();
      off.asms_on = false;
      EXPECT_EQ(m.update(30 * kMs, off), AsState::Off) << c.name;
    }
  }
}

TEST(AsMachine, AsmsOffIsOffWhenReadyAndAnEmergencyWhenDriving) {
  AsInputs off = ready_car();
  off.asms_on = false;
  AsMachine ready{AsParams{}};
  ready.update(0, ready_car());
  EXPECT_EQ(ready.update(10 * kMs, off), AsState::Off);
  AsMachine d = driving();
  EXPECT_EQ(d.update(10 * kMs, off), AsState::Emergency);
  EXPECT_EQ(d.transitions().back().reason, "ASMS switched off while driving");
}

TEST(AsMachine, FinishedAfterTheMissionThenOffOrEmergency) {
  AsMachine m = driving();
  AsInputs done = ready_car();
  done.mission_done = true;
  EXPECT_EQ(m.update(10 * kMs, done), AsState::Finished);
  // a fault after the finish changes nothing (the car is at rest, braked)
  AsInputs fault = done;
  fault.fault = "watchdog";
  EXPECT_EQ(m.update(20 * kMs, fault), AsState::Finished);
  AsInputs res = done;
  res.res_emergency = true;
  AsMachine n = driving();
  n.update(10 * kMs, done);
  EXPECT_EQ(n.update(20 * kMs, res), AsState::Emergency);
  AsInputs off = done;
  off.asms_on = false;
  EXPECT_EQ(m.update(30 * kMs, off), AsState::Off);
}

TEST(AsMachine, AFaultInOffKeepsItOffNotEmergency) {
  AsMachine m{AsParams{}};
  AsInputs in = ready_car();
  in.fault = "watchdog: no sensor frame on the CAN bus";
  EXPECT_EQ(m.update(0, in), AsState::Off);
  EXPECT_EQ(m.waiting_for(), in.fault);
}

}  // namespace
}  // namespace paddock::stack
