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

TEST(AgentSilence, AStalledPortLosesNoAgentThatWasHeardBeforeIt) {
  // The server's receive stalled for 1 s (a killed agent held its port's
  // lock): the other agents silent for 0.7 s, one of them for 1.0 s. The
  // latter is not lost; with the old rule (the whole swarm silent for a whole
  // timeout) it was.
  EXPECT_GT(agent_silence_limit(10.0, 9.3, 1.0), 1.0);
  // A single dead agent among live ones is still lost after one timeout:
  // the others' heartbeats (4 a second) keep the newest within 0.25 s.
  EXPECT_DOUBLE_EQ(agent_silence_limit(10.0, 9.75, 1.0), 1.0);
}
