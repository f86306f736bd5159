#include "sim_server/mission_ring.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "common/mission.hpp"

using namespace ddswarm;

namespace {

msg::MissionCommand cmd(std::uint32_t seq, MissionType t) {
  msg::MissionCommand m;
  m.seq(seq);
  m.type(static_cast<std::uint8_t>(t));
  return m;
}

std::vector<std::uint32_t> seqs(const std::deque<msg::MissionCommand>& r) {
  std::vector<std::uint32_t> v;
  for (const auto& m : r) v.push_back(m.seq());
  return v;
}

}  // namespace

TEST(MissionRing, KeepsTheCommandsThatDefineTheMissionThroughATeleopStorm) {
  // takeoff, distance, follow, then many teleops: a (re)joining agent must
  // still find takeoff, distance and follow in the ring.
  std::deque<msg::MissionCommand> ring;
  ring.push_back(cmd(1, MissionType::kTakeoff));
  ring.push_back(cmd(2, MissionType::kSetDistance));
  ring.push_back(cmd(3, MissionType::kFollowLeader));
  for (std::uint32_t s = 4; s < 40; ++s) {
    ring.push_back(cmd(s, MissionType::kTeleop));
    sim::trim_recent(ring, 8);
  }
  EXPECT_EQ(seqs(ring), (std::vector<std::uint32_t>{1, 2, 3, 35, 36, 37, 38, 39}));
}

TEST(MissionRing, DropsTheOldestSupersededFirst) {
  std::deque<msg::MissionCommand> ring;
  ring.push_back(cmd(1, MissionType::kTakeoff));
  ring.push_back(cmd(2, MissionType::kMove));
  ring.push_back(cmd(3, MissionType::kHold));
  ring.push_back(cmd(4, MissionType::kTask));
  sim::trim_recent(ring, 3);
  EXPECT_EQ(seqs(ring), (std::vector<std::uint32_t>{1, 3, 4}));
  sim::trim_recent(ring, 2);
  EXPECT_EQ(seqs(ring), (std::vector<std::uint32_t>{1, 4}));  // takeoff stays: the altitude class
  sim::trim_recent(ring, 1);
  EXPECT_EQ(seqs(ring), (std::vector<std::uint32_t>{4}));  // nothing superseded: the oldest goes
}

TEST(MissionRing, UnknownTypesAreDroppedBeforeAnythingThatDefinesTheMission) {
  std::deque<msg::MissionCommand> ring;
  ring.push_back(cmd(1, MissionType::kTakeoff));
  ring.push_back(cmd(2, static_cast<MissionType>(99)));
  ring.push_back(cmd(3, MissionType::kTask));
  sim::trim_recent(ring, 2);
  EXPECT_EQ(seqs(ring), (std::vector<std::uint32_t>{1, 3}));
}
