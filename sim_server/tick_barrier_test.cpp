#include "sim_server/tick_barrier.hpp"

#include <gtest/gtest.h>

#include <vector>

using namespace ddswarm::sim;

namespace {

/// A drone's agent as the server sees it, for the barrier's publish.
struct Agents {
  std::vector<CommandView> v;
  explicit Agents(int n) : v(static_cast<std::size_t>(n)) {}
  void command(int i, std::uint64_t tick, double vx) {
    v[i].live = true;
    v[i].has_command = true;
    v[i].command_tick = tick;
    v[i].setpoint.v_world = {vx, 0, 0};
    v[i].setpoint.motors_on = true;
  }
  auto now() const {
    return [this](int i) { return v[i]; };
  }
};

}  // namespace

TEST(TickBarrier, LockstepWaitsForEveryLiveAgentAndWakesOnTheLastAnswer) {
  TickBarrier b(3, Pipeline::kNone);
  Agents a(3);
  a.v[0].live = a.v[1].live = true;  // drone 2 has no agent
  b.publish(7, a.now());
  EXPECT_EQ(b.published(), 7u);
  EXPECT_EQ(b.waiting(), 2);
  a.command(0, 7, 1.0);
  EXPECT_FALSE(b.answer(0, 7, a.v[0]));
  EXPECT_EQ(b.waiting(), 1);
  a.command(1, 7, 1.0);
  EXPECT_TRUE(b.answer(1, 7, a.v[1]));  // the last one: wake the loop
  EXPECT_EQ(b.waiting(), 0);
}

TEST(TickBarrier, AnAnswerToATickPublishedAgainCountsOnce) {
  // Lockstep resends the state of a tick whose answers are late; every agent
  // answers it again. The barrier counts each agent once.
  TickBarrier b(2, Pipeline::kNone);
  Agents a(2);
  a.v[0].live = a.v[1].live = true;
  b.publish(3, a.now());
  a.command(0, 3, 1.0);
  EXPECT_FALSE(b.answer(0, 3, a.v[0]));
  EXPECT_FALSE(b.answer(0, 3, a.v[0]));  // the resend's repeat
  EXPECT_EQ(b.waiting(), 1);
  // An answer to an older tick does not answer this one.
  EXPECT_FALSE(b.answer(1, 2, a.v[1]));
  EXPECT_EQ(b.waiting(), 1);
  EXPECT_TRUE(b.answer(1, 3, a.v[1]));
  EXPECT_EQ(b.waiting(), 0);
}

TEST(TickBarrier, AJoinerOwesTheTickAndALostAgentOwesNothing) {
  TickBarrier b(3, Pipeline::kNone);
  Agents a(3);
  a.v[0].live = true;
  b.publish(10, a.now());
  a.command(0, 10, 0.5);
  EXPECT_TRUE(b.answer(0, 10, a.v[0]));
  EXPECT_EQ(b.waiting(), 0);
  // Agent 1 is heard mid-tick: the loop now waits for it too.
  const int owed_prev = b.unanswered_prev();
  b.join(1);
  EXPECT_EQ(b.waiting(), 1);
  EXPECT_EQ(b.unanswered_prev(),
            owed_prev);  // it owes nothing to a tick published before it was heard
  // Agent 1 is lost before answering: nothing is owed any more.
  b.lose(1);
  EXPECT_EQ(b.waiting(), 0);
  // Losing an agent that already answered changes nothing.
  b.lose(0);
  EXPECT_EQ(b.waiting(), 0);
  // The next tick counts only the agents live at its publish.
  a.v[1].live = a.v[2].live = true;
  a.v[0].live = false;
  b.publish(11, a.now());
  EXPECT_EQ(b.waiting(), 2);
}

TEST(TickBarrier, LockstepPipelineFliesTheCommandsLatchedWhenTheTickWentOut) {
  // Tick k goes out with the answers to k-1 latched: those fly k -> k+1
  // while the agents answer k; their answers fly only after k+1 goes out.
  TickBarrier b(1, Pipeline::kLockstep);
  Agents a(1);
  a.command(0, 4, 1.0);  // the answer to tick 4
  b.publish(5, a.now());
  EXPECT_EQ(b.waiting(), 1);
  EXPECT_DOUBLE_EQ(b.latched(0).setpoint.v_world.x(), 1.0);
  EXPECT_EQ(b.latched(0).command_tick, 4u);
  a.command(0, 5, 2.0);  // the answer to tick 5 comes in
  EXPECT_TRUE(b.answer(0, 5, a.v[0]));
  EXPECT_EQ(b.waiting(), 0);
  EXPECT_DOUBLE_EQ(b.latched(0).setpoint.v_world.x(), 1.0);  // still the answer to 4
  b.publish(6, a.now());
  EXPECT_DOUBLE_EQ(b.latched(0).setpoint.v_world.x(), 2.0);
  EXPECT_EQ(b.latched(0).command_tick, 5u);
  // A late answer to 5 after 6 went out does not change the latch either.
  a.command(0, 5, 3.0);
  EXPECT_FALSE(b.answer(0, 5, a.v[0]));
  EXPECT_DOUBLE_EQ(b.latched(0).setpoint.v_world.x(), 2.0);
}

TEST(TickBarrier, RealtimePipelineWaitsForTheAnswersToTheTickBefore) {
  // Real time, pipelined: tick k goes out on its period's edge, then the world
  // steps with the answers to k-1, waiting for those that are late.
  TickBarrier b(2, Pipeline::kRealtime);
  Agents a(2);
  b.publish(0, a.now());
  // Both agents are heard after tick 0 went out: they owe it, and nothing before it.
  b.join(0);
  b.join(1);
  a.v[0].live = a.v[1].live = true;
  EXPECT_EQ(b.waiting(), 0);
  EXPECT_EQ(b.unanswered(), 2);
  a.command(0, 0, 1.0);
  EXPECT_FALSE(b.answer(0, 0, a.v[0]));
  b.publish(1, a.now());  // drone 1 has not answered tick 0
  EXPECT_EQ(b.waiting(), 1);
  EXPECT_EQ(b.unanswered_prev(), 1);
  EXPECT_EQ(b.unanswered(), 2);
  EXPECT_DOUBLE_EQ(b.latched(0).setpoint.v_world.x(), 1.0);
  EXPECT_FALSE(b.latched(1).has_command);
  // Drone 1's late answer to 0 still flies the coming step: latched, and the
  // last answer the step waits for.
  a.command(1, 0, 2.0);
  EXPECT_TRUE(b.answer(1, 0, a.v[1]));
  EXPECT_EQ(b.waiting(), 0);
  EXPECT_DOUBLE_EQ(b.latched(1).setpoint.v_world.x(), 2.0);
  // An answer to the tick just published waits for the step after it.
  a.command(0, 1, 5.0);
  EXPECT_FALSE(b.answer(0, 1, a.v[0]));
  EXPECT_DOUBLE_EQ(b.latched(0).setpoint.v_world.x(), 1.0);
  EXPECT_EQ(b.unanswered(), 1);
}

TEST(TickBarrier, RealtimePipelineReleasesTheStepWhenTheLateAgentIsLost) {
  TickBarrier b(2, Pipeline::kRealtime);
  Agents a(2);
  b.publish(0, a.now());
  b.join(0);
  b.join(1);
  a.v[0].live = a.v[1].live = true;
  b.publish(1, a.now());  // neither answered tick 0
  EXPECT_EQ(b.waiting(), 2);
  b.lose(1);
  EXPECT_EQ(b.waiting(), 1);
  EXPECT_EQ(b.unanswered(), 1);
}

TEST(TickBarrier, WithoutAPipelineTheWaitIsForThePublishedTick) {
  // Real time without a pipeline waits, up to the grace, for the answers to
  // the published tick, as lockstep does without one.
  for (Pipeline p : {Pipeline::kNone, Pipeline::kLockstep}) {
    TickBarrier b(1, p);
    Agents a(1);
    a.v[0].live = true;
    b.publish(0, a.now());
    b.publish(1, a.now());
    EXPECT_EQ(b.unanswered_prev(), 1);
    EXPECT_EQ(b.waiting(), 1);
    a.command(0, 0, 1.0);
    EXPECT_FALSE(b.answer(0, 0, a.v[0]));  // a late answer to 0 does not answer 1
    EXPECT_EQ(b.waiting(), 1);
  }
}
