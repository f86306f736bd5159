// The pace of a replay: held only where a fast replay could crash a joining
// reader (docs/dds.md), never below the pace the recording ran at live.
#include <gtest/gtest.h>

#include "recorder/recorder.hpp"

namespace ddswarm::gs {
namespace {

TEST(ReplayRate, AFastReplayOfABusyTopicIsHeldToTheSafeRate) {
  // Six drones in lockstep: 2,783 states a second recorded, asked 10x.
  EXPECT_DOUBLE_EQ(replay_rate(10, 2783), kReplayMaxSamplesPerS / 2783);
  EXPECT_LE(replay_rate(10, 2783) * 2783, kReplayMaxSamplesPerS);
}

TEST(ReplayRate, WhatStaysUnderTheSafeRateIsPlayedAsAsked) {
  EXPECT_DOUBLE_EQ(replay_rate(20, 50), 20);  // real time at 50 Hz, 1,000 a second
  EXPECT_DOUBLE_EQ(replay_rate(2, 5000), 2);  // exactly the safe rate
}

TEST(ReplayRate, NeverSlowerThanAsked1OrTheRecordingsOwnPace) {
  EXPECT_DOUBLE_EQ(replay_rate(1, 1e6), 1);      // as recorded: it ran live
  EXPECT_DOUBLE_EQ(replay_rate(0.5, 1e6), 0.5);  // slower than recorded
  EXPECT_DOUBLE_EQ(replay_rate(100, 20000), 1);  // held, but not below 1
}

}  // namespace
}  // namespace ddswarm::gs
