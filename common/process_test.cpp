#include "common/process.hpp"

#include <gtest/gtest.h>

namespace ddswarm {
namespace {

TEST(LeaseWatch, AGapLongerThanTheLeaseSaysWhyToJoinAgain) {
  LeaseWatch w(3.0, 100.0);
  EXPECT_EQ(w.turn(100.25), "");
  EXPECT_EQ(w.turn(103.25), "");  // exactly the lease: peers have not dropped it yet
  EXPECT_EQ(w.turn(112.95),
            "this process was stopped or starved for 9.7 s, longer than its DDS lease (3.0 s, "
            "dds.lease_duration_s); leaving DDS and joining again as a new participant");
  EXPECT_EQ(w.turn(113.0), "");  // each gap is measured from the turn before
}

TEST(LeaseWatch, RestartLeavesOwnWorkOutOfTheGap) {
  LeaseWatch w(3.0, 0.0);
  w.restart(10.0);  // e.g. after joining again, which takes its own time
  EXPECT_EQ(w.turn(10.5), "");
}

TEST(RejoinPatience, DoublesAtEachTryUpToEightTimes) {
  EXPECT_EQ(rejoin_patience_s(20.0, 0), 20.0);
  EXPECT_EQ(rejoin_patience_s(20.0, 1), 40.0);
  EXPECT_EQ(rejoin_patience_s(20.0, 2), 80.0);
  EXPECT_EQ(rejoin_patience_s(20.0, 3), 160.0);
  EXPECT_EQ(rejoin_patience_s(20.0, 30), 160.0);  // no overflow, no endless growth
  EXPECT_EQ(rejoin_patience_s(10.0, -1), 10.0);
}

}  // namespace
}  // namespace ddswarm
