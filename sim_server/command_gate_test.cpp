#include "sim_server/command_gate.hpp"

#include <gtest/gtest.h>

#include <limits>

using namespace ddswarm::sim;

namespace {
CommandFacts ok_cmd() { return {2, 10, {1, 0, 0}, 0.0, 42}; }
GateContext ctx() { return {6, 10, 10, 42, 50.0}; }
}  // namespace

TEST(CommandGate, AcceptsAWellFormedCommandForTheCurrentTick) {
  EXPECT_EQ(check_command(ok_cmd(), ctx()), Verdict::kAccept);
}

TEST(CommandGate, RejectsNonFiniteValues) {
  auto c = ok_cmd();
  c.velocity.y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(check_command(c, ctx()), Verdict::kNonFinite);
  c = ok_cmd();
  c.yaw_rate = std::numeric_limits<double>::infinity();
  EXPECT_EQ(check_command(c, ctx()), Verdict::kNonFinite);
}

TEST(CommandGate, RejectsAbsurdSpeedUnknownIdsAndImpostors) {
  auto c = ok_cmd();
  c.velocity = {300, 0, 0};
  EXPECT_EQ(check_command(c, ctx()), Verdict::kAbsurd);
  c = ok_cmd();
  c.drone_id = 6;
  EXPECT_EQ(check_command(c, ctx()), Verdict::kUnknownId);
  c.drone_id = -1;
  EXPECT_EQ(check_command(c, ctx()), Verdict::kUnknownId);
  c = ok_cmd();
  c.instance = 43;
  EXPECT_EQ(check_command(c, ctx()), Verdict::kImpostor);
  auto g = ctx();
  g.owner_instance = 0;  // nobody owns the drone yet: the first agent may claim it
  EXPECT_EQ(check_command(c, g), Verdict::kAccept);
}

TEST(CommandGate, RejectsStaleAndFutureTicks) {
  auto c = ok_cmd();
  c.tick = 9;
  EXPECT_EQ(check_command(c, ctx()), Verdict::kStaleTick);
  c.tick = 11;
  EXPECT_EQ(check_command(c, ctx()), Verdict::kFutureTick);
}

TEST(CommandGate, TellsARepeatedAnswerFromAStaleOne) {
  // Lockstep, collecting tick 10; the owner's applied answer was for tick 9.
  // The tick went out twice, so its answer to 9 came twice: a repeat. Any
  // other old tick is stale, and the gate knows no repeat without a last answer.
  auto g = ctx();
  g.answered_tick = 9;
  auto c = ok_cmd();
  c.tick = 9;
  EXPECT_EQ(check_command(c, g), Verdict::kRepeat);
  c.tick = 8;
  EXPECT_EQ(check_command(c, g), Verdict::kStaleTick);
  c.tick = 9;
  c.instance = 99;  // someone else's answer to tick 9 is an impostor's
  EXPECT_EQ(check_command(c, g), Verdict::kImpostor);
  c.instance = ok_cmd().instance;
  EXPECT_EQ(check_command(c, ctx()), Verdict::kStaleTick);
}
