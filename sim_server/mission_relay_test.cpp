#include "sim_server/mission_relay.hpp"

#include <gtest/gtest.h>

#include "common/mission.hpp"

using namespace ddswarm;
using namespace ddswarm::sim;
using Intake = MissionRelay::Intake;

namespace {

msg::MissionCommand cmd(std::uint32_t seq, MissionType t, std::uint64_t issuer = 7) {
  msg::MissionCommand m;
  m.seq(seq);
  m.type(static_cast<std::uint8_t>(t));
  m.issuer_instance(issuer);
  return m;
}

}  // namespace

TEST(MissionRelay, RefusesMalformedCommandsAndThoseForAnotherServer) {
  MissionRelay r(0x51);
  std::string problem;
  EXPECT_EQ(r.take(cmd(1, MissionType::kNone), problem), Intake::kMalformed);
  EXPECT_EQ(problem, "unknown command type 0");
  auto m = cmd(2, MissionType::kTakeoff);
  m.server_instance(0x52);
  EXPECT_EQ(r.take(m, problem), Intake::kStale);
  EXPECT_FALSE(r.begun());
  EXPECT_FALSE(r.pending());
  m.server_instance(0x51);
  EXPECT_EQ(r.take(m, problem), Intake::kNew);
  EXPECT_TRUE(problem.empty());
  EXPECT_TRUE(r.begun());
  EXPECT_TRUE(r.pending());
}

TEST(MissionRelay, ReleasesOneNewCommandPerTickStampedWithIt) {
  MissionRelay r(0x51);
  std::string problem;
  r.take(cmd(1, MissionType::kTakeoff), problem);
  r.take(cmd(2, MissionType::kHold), problem);
  auto m = r.release(10);
  ASSERT_TRUE(m);
  EXPECT_EQ(m->seq(), 1u);
  m = r.release(11);
  ASSERT_TRUE(m);
  EXPECT_EQ(m->seq(), 2u);
  EXPECT_FALSE(r.release(12));
  ASSERT_EQ(r.ring().size(), 2u);
  EXPECT_EQ(r.ring()[0].apply_tick(), 10u);
  EXPECT_EQ(r.ring()[1].apply_tick(), 11u);
}

TEST(MissionRelay, ARepeatTakesNoSlotAndKeepsOneRingEntry) {
  MissionRelay r(0x51);
  std::string problem;
  r.take(cmd(1, MissionType::kTakeoff), problem);
  ASSERT_TRUE(r.release(10));
  EXPECT_EQ(r.take(cmd(1, MissionType::kTakeoff), problem), Intake::kRepeat);
  r.take(cmd(2, MissionType::kHold), problem);
  // The repeat goes into the ring again, stamped anew; the new command is
  // still released on this very tick.
  const auto m = r.release(20);
  ASSERT_TRUE(m);
  EXPECT_EQ(m->seq(), 2u);
  ASSERT_EQ(r.ring().size(), 2u);
  EXPECT_EQ(r.ring()[0].seq(), 1u);
  EXPECT_EQ(r.ring()[0].apply_tick(), 20u);
  EXPECT_EQ(r.ring()[1].seq(), 2u);
  // The same seq from another issuer is another command.
  EXPECT_EQ(r.take(cmd(1, MissionType::kTakeoff, 8), problem), Intake::kNew);
}

TEST(MissionRelay, KeepsTheDistanceTheLastReleasedSetDistanceCommandSet) {
  MissionRelay r(0x51);
  std::string problem;
  EXPECT_DOUBLE_EQ(r.distance_m(), 0.0);
  auto m = cmd(1, MissionType::kSetDistance);
  m.value(3.5);
  ASSERT_EQ(r.take(m, problem), Intake::kNew);
  EXPECT_DOUBLE_EQ(r.distance_m(), 0.0);  // not before its release
  ASSERT_TRUE(r.release(5));
  EXPECT_DOUBLE_EQ(r.distance_m(), 3.5);
  r.take(cmd(2, MissionType::kTakeoff), problem);
  ASSERT_TRUE(r.release(6));
  EXPECT_DOUBLE_EQ(r.distance_m(), 3.5);
}
