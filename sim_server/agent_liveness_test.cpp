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
  // The server's receive stalls for 1 s (a killed agent holds its port's
  // lock): the other agents silent for 0.7 s, one of them for 1.0 s. The
  // latter is not lost, as it would be if only a whole swarm silent for a
  // whole timeout lengthened the limit.
  EXPECT_GT(agent_silence_limit(10.0, 9.3, 1.0), 1.0);
  // A single dead agent among live ones is still lost after one timeout:
  // the others' heartbeats (4 a second) keep the newest within 0.25 s.
  EXPECT_DOUBLE_EQ(agent_silence_limit(10.0, 9.75, 1.0), 1.0);
}

TEST(AgentSilence, AgentsQueuedBehindTheFirstOneHeardAfterAStallAreNotLost) {
  // As in mp_fault_agent_kill: agent 3 is killed at t = 9.40, the server's
  // port stalls until 10.40; agents 1 and 5 come in first, and 0, 2 and 4
  // four milliseconds later, each last heard at 9.39.
  SwarmSilence watch;
  EXPECT_DOUBLE_EQ(watch.limit(9.80, 9.39, 1.0), 1.0);
  EXPECT_FALSE(watch.silent());
  EXPECT_DOUBLE_EQ(watch.limit(10.00, 9.39, 1.0), kSilentSwarmTimeouts);  // the swarm is silent
  EXPECT_TRUE(watch.silent());
  const double t = watch.limit(10.40, 10.40, 1.0);  // agent 1 heard again
  EXPECT_DOUBLE_EQ(t, 1.0);
  EXPECT_FALSE(watch.silent());
  EXPECT_LE(10.40 - watch.silent_since(9.39), t) << "agent 0, queued behind agent 1, is not lost";
  // Agent 3 stays silent: lost one timeout after the stall ended.
  watch.limit(11.30, 11.25, 1.0);
  EXPECT_LE(11.30 - watch.silent_since(9.39), 1.0);
  watch.limit(11.45, 11.40, 1.0);
  EXPECT_GT(11.45 - watch.silent_since(9.39), 1.0);
  // An agent heard since counts from its own word.
  EXPECT_DOUBLE_EQ(watch.silent_since(11.40), 11.40);
}

TEST(AgentSilence, WithoutAStallADeadAgentIsLostAfterOneTimeout) {
  SwarmSilence watch;  // the others' heartbeats keep the newest within 0.25 s
  const double t = watch.limit(10.30, 10.20, 1.0);
  EXPECT_GT(10.30 - watch.silent_since(9.25), t);
  EXPECT_FALSE(watch.silent());
}

TEST(AgentSilence, SeveralAgentsPastTheLimitAtOnceWaitOutAPortStall) {
  // As in mp_fault_agent_kill: agent 3 is killed at 9.65; agent 4 keeps
  // being heard, so the swarm is never silent; agents 0, 1, 2, 3 and 5, last
  // heard at 9.65, pass the 1 s limit together at 10.656, and all but 3 are
  // heard again at 10.657.
  SwarmSilence watch;
  const double t = watch.limit(10.656, 10.40, 1.0);  // agent 4's heartbeat at 10.40
  EXPECT_DOUBLE_EQ(t, 1.0);
  EXPECT_FALSE(declare_lost_now(5, 10.656 - 9.65, t)) << "five at once: a stalled port, held";
  // 10.657: four are back; the killed agent alone is past the limit: lost.
  EXPECT_TRUE(declare_lost_now(1, 10.657 - 9.65, t));
  // Five that stay silent (say, an agent-host process killed) are lost one
  // port-lock timeout later.
  EXPECT_FALSE(declare_lost_now(5, 1.0 + kPortLockTimeoutS, 1.0));
  EXPECT_TRUE(declare_lost_now(5, 1.01 + kPortLockTimeoutS, 1.0));
}

TEST(AgentSilence, OneAgentPastTheLimitIsLostAtOnce) {
  EXPECT_TRUE(declare_lost_now(1, 1.01, 1.0));
  EXPECT_TRUE(declare_lost_now(0, 0, 1.0));  // nobody past: nothing to hold
}
