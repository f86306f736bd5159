#include "sim_server/agent_liveness.hpp"

#include <gtest/gtest.h>

using namespace ddswarm::sim;

TEST(AgentSilence, AServerStallDoesNotLoseTheWholeSwarm) {
  // One agent heard 0.2 s ago: another silent for 1.5 s is lost after the 1 s timeout.
  EXPECT_DOUBLE_EQ(agent_silence_limit(10.0, 9.8, 1.0), 1.0);
  // Nobody heard for 1.5 s: the silence may be the server's; wait three timeouts.
  EXPECT_DOUBLE_EQ(agent_silence_limit(10.0, 8.5, 1.0), kSilentSwarmTimeouts * 1.0);
  // So a 2.5 s stall of the server's receive threads loses nobody.
  EXPECT_GT(agent_silence_limit(10.0, 7.5, 1.0), 2.5);
}
