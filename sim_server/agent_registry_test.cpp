#include "sim_server/agent_registry.hpp"

#include <gtest/gtest.h>

using namespace ddswarm;
using namespace ddswarm::sim;

namespace {

CommandFacts facts(int id, std::uint64_t tick, std::uint64_t instance) {
  return {id, tick, Eigen::Vector3d(1, 0, 0), 0.0, instance};
}

CommandRecord rec(std::uint64_t tick, Phase phase = Phase::kHold) {
  CommandRecord r;
  r.setpoint.v_world = {1, 0, 0};
  r.setpoint.motors_on = true;
  r.tick = tick;
  r.phase = phase;
  return r;
}

}  // namespace

TEST(AgentRegistry, AHeartbeatBringsAnAgentOnlineAndRefusesImpostors) {
  AgentRegistry reg(2, true, Pipeline::kNone);
  EXPECT_EQ(reg.heartbeat(5, 0xa, 1.0), AgentRegistry::Heard::kUnknownId);
  EXPECT_EQ(reg.heartbeat(0, 0xa, 1.0), AgentRegistry::Heard::kOnline);
  EXPECT_TRUE(reg[0].live);
  EXPECT_EQ(reg[0].owner, 0xau);
  EXPECT_EQ(reg.barrier().waiting(), 1);  // a new agent owes the published tick
  EXPECT_EQ(reg.heartbeat(0, 0xa, 1.2), AgentRegistry::Heard::kHeard);
  EXPECT_DOUBLE_EQ(reg[0].last_heard_wall_s, 1.2);
  EXPECT_EQ(reg.heartbeat(0, 0xb, 1.3), AgentRegistry::Heard::kImpostor);
  EXPECT_EQ(reg[0].owner, 0xau);
  EXPECT_DOUBLE_EQ(reg[0].last_heard_wall_s, 1.2);
}

TEST(AgentRegistry, TheGateSeesTheOwnerAndTheTicksALockstepAgentAnswered) {
  AgentRegistry reg(1, true, Pipeline::kNone);
  reg.publish(3);
  ASSERT_EQ(reg.heartbeat(0, 0xa, 0.0), AgentRegistry::Heard::kOnline);
  EXPECT_EQ(reg.check(facts(0, 3, 0xb), 50), Verdict::kImpostor);
  EXPECT_EQ(reg.check(facts(0, 2, 0xa), 50), Verdict::kStaleTick);
  EXPECT_EQ(reg.check(facts(0, 4, 0xa), 50), Verdict::kFutureTick);
  ASSERT_EQ(reg.check(facts(0, 3, 0xa), 50), Verdict::kAccept);
  const auto r = reg.record(0, 0xa, rec(3), 0.1);
  EXPECT_FALSE(r.online);
  EXPECT_TRUE(r.status_due);  // its phase changed
  EXPECT_TRUE(r.wake);
  EXPECT_FALSE(r.late);
  // Tick 4 goes out; the resend of 3 is answered again: a repeat, dropped.
  reg.publish(4);
  EXPECT_EQ(reg.check(facts(0, 3, 0xa), 50), Verdict::kRepeat);
  EXPECT_EQ(reg.check(facts(1, 4, 0xa), 50), Verdict::kUnknownId);
}

TEST(AgentRegistry, RealTimeAcceptsTheNewestAnswerAndCountsItLate) {
  AgentRegistry reg(1, false, Pipeline::kNone);
  reg.publish(10);
  ASSERT_EQ(reg.check(facts(0, 8, 0xa), 50), Verdict::kAccept);
  auto r = reg.record(0, 0xa, rec(8), 0.0);
  EXPECT_TRUE(r.online);
  EXPECT_TRUE(r.late);
  EXPECT_EQ(reg[0].command_tick, 8u);
  EXPECT_EQ(reg.check(facts(0, 7, 0xa), 50), Verdict::kStaleTick);  // older than its last
  r = reg.record(0, 0xa, rec(10), 0.0);
  EXPECT_FALSE(r.late);
  EXPECT_FALSE(r.status_due);  // same mission, same phase
  EXPECT_TRUE(r.wake);
}

TEST(AgentRegistry, ASilentAgentIsLostAndOwesNoAnswer) {
  AgentRegistry reg(2, true, Pipeline::kNone);
  reg.heartbeat(0, 0xa, 0.0);
  reg.heartbeat(1, 0xb, 0.0);
  reg.publish(1);
  EXPECT_EQ(reg.barrier().waiting(), 2);
  reg.heartbeat(0, 0xa, 1.4);
  const auto e = reg.expire(1.5, 1.0);
  EXPECT_FALSE(e.silence_began);
  ASSERT_EQ(e.lost.size(), 1u);
  EXPECT_EQ(e.lost[0].first, 1);
  EXPECT_DOUBLE_EQ(e.lost[0].second, 1.5);
  EXPECT_FALSE(reg[1].live);
  EXPECT_EQ(reg[1].owner, 0u);
  EXPECT_EQ(reg.barrier().waiting(), 1);
  // Another instance may now fly drone 1.
  EXPECT_EQ(reg.heartbeat(1, 0xc, 1.6), AgentRegistry::Heard::kOnline);
}

TEST(AgentRegistry, AWholeSwarmSilenceIsWaitedOut) {
  AgentRegistry reg(2, true, Pipeline::kNone);
  reg.heartbeat(0, 0xa, 0.0);
  reg.heartbeat(1, 0xb, 0.0);
  auto e = reg.expire(1.5, 1.0);  // nobody heard for 1.5 s: may be this server's stall
  EXPECT_TRUE(e.silence_began);
  EXPECT_DOUBLE_EQ(e.limit_s, kSilentSwarmTimeouts * 1.0);
  EXPECT_DOUBLE_EQ(e.newest_silence_s, 1.5);
  EXPECT_TRUE(e.lost.empty());
  e = reg.expire(2.0, 1.0);
  EXPECT_FALSE(e.silence_began);  // said once
  EXPECT_TRUE(e.lost.empty());
  EXPECT_TRUE(reg[0].live && reg[1].live);
}

TEST(AgentRegistry, SeveralPastTheLimitAtOnceAreHeldForThePortLock) {
  AgentRegistry reg(3, true, Pipeline::kNone);
  reg.heartbeat(0, 0xa, 0.0);
  reg.heartbeat(1, 0xb, 0.0);
  reg.heartbeat(2, 0xc, 1.2);  // keeps the swarm from being silent
  auto e = reg.expire(1.3, 1.0);
  EXPECT_TRUE(e.holding_began);
  EXPECT_EQ(e.past_limit, 2);
  EXPECT_TRUE(e.lost.empty());
  reg.heartbeat(2, 0xc, 1.5);
  e = reg.expire(1.6, 1.0);
  EXPECT_FALSE(e.holding_began);  // still held, said once
  EXPECT_TRUE(e.lost.empty());
  reg.heartbeat(2, 0xc, 2.0);
  e = reg.expire(2.1, 1.0);  // 2.1 s silent > 1 s + kPortLockTimeoutS: both lost
  EXPECT_EQ(e.lost.size(), 2u);
  EXPECT_TRUE(reg[2].live);
}

TEST(AgentRegistry, TheSwarmIsIdleWhenNoLiveAgentIsBusy) {
  AgentRegistry reg(2, true, Pipeline::kNone);
  EXPECT_TRUE(reg.idle());
  reg.publish(0);
  reg.heartbeat(0, 0xa, 0.0);
  auto r = rec(0);
  r.busy = true;
  reg.record(0, 0xa, r, 0.0);
  EXPECT_FALSE(reg.idle());
  reg.expire(5.0, 1.0);  // the busy one is lost
  EXPECT_TRUE(reg.idle());
}
