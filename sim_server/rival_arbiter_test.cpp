#include "sim_server/rival_arbiter.hpp"

#include <gtest/gtest.h>

using namespace ddswarm::sim;
using Move = RivalArbiter::Move;

TEST(RivalArbiter, TheNewerServerLeavesAndTheOlderSaysSoOnce) {
  RivalArbiter a;
  a.published(1000);
  EXPECT_EQ(a.on_scene(900, 5000, false), Move::kLeave);  // the other joined first
  RivalArbiter b;
  b.published(900);
  EXPECT_EQ(b.on_scene(1000, 5000, false), Move::kStayAndSay);
  EXPECT_EQ(b.on_scene(1000, 5000, false), Move::kStay);
}

TEST(RivalArbiter, AServerWithAMissionNeverLeaves) {
  RivalArbiter a;
  a.published(1000);
  EXPECT_EQ(a.on_scene(1, 5000, true), Move::kStayAndSay);
  EXPECT_FALSE(RivalArbiter::leaves_for_status(true, {3, 4}));
}

TEST(RivalArbiter, AServerWithoutOneLeavesForASwarmWithAMission) {
  EXPECT_TRUE(RivalArbiter::leaves_for_status(false, {0, 0, 2}));
  EXPECT_FALSE(RivalArbiter::leaves_for_status(false, {0, 0, 0}));
  EXPECT_FALSE(RivalArbiter::leaves_for_status(false, {}));
}

TEST(RivalArbiter, BeforeItsSceneGoesOutNowStandsForItsTimestamp) {
  RivalArbiter a;
  EXPECT_EQ(a.on_scene(900, 1000, false), Move::kLeave);
  EXPECT_EQ(a.on_scene(1100, 1000, false), Move::kStayAndSay);
}
