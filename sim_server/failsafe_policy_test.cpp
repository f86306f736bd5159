#include "sim_server/failsafe_policy.hpp"

#include <gtest/gtest.h>

using namespace ddswarm::sim;
using Change = SetpointChoice::Change;

namespace {

constexpr FailsafeRules kRules{0.02, 0.5, 5.0};  // 50 Hz, 0.5 s command timeout, land after 5 s

CommandView command(std::uint64_t tick, double vx, bool live = true) {
  CommandView c;
  c.setpoint.v_world = {vx, 0, 0};
  c.setpoint.motors_on = true;
  c.has_command = true;
  c.command_tick = tick;
  c.live = live;
  return c;
}

}  // namespace

TEST(FailsafePolicy, AFreshCommandFliesWithItsAge) {
  FailsafePolicy p(1, kRules);
  const auto ch = p.choose(0, command(95, 2.0), 100, true, {});
  EXPECT_TRUE(ch.fresh);
  EXPECT_EQ(ch.change, Change::kNone);
  EXPECT_DOUBLE_EQ(ch.setpoint.v_world.x(), 2.0);
  EXPECT_FLOAT_EQ(ch.command_age_s, 0.1f);
  EXPECT_FALSE(p.active(0));
}

TEST(FailsafePolicy, ADroneIdleOnTheGroundIsNotInFailsafe) {
  FailsafePolicy p(1, kRules);
  VelocitySetpoint off;
  const auto ch = p.choose(0, CommandView{}, 100, false, off);
  EXPECT_FALSE(ch.fresh);
  EXPECT_EQ(ch.change, Change::kNone);
  EXPECT_FALSE(ch.setpoint.motors_on);
  EXPECT_FALSE(p.active(0));
}

TEST(FailsafePolicy, WithoutAFreshCommandItHoversThenLands) {
  FailsafePolicy p(1, kRules);
  VelocitySetpoint flying;
  flying.motors_on = true;
  flying.v_world = {3, 0, 0};
  // The last command, for tick 100, is older than 0.5 s at tick 126.
  auto ch = p.choose(0, command(100, 3.0), 126, true, flying);
  EXPECT_FALSE(ch.fresh);
  EXPECT_EQ(ch.change, Change::kEntered);
  EXPECT_TRUE(p.active(0));
  EXPECT_TRUE(ch.setpoint.motors_on);
  EXPECT_EQ(ch.setpoint.v_world, Eigen::Vector3d::Zero());  // hover in place
  ch = p.choose(0, command(100, 3.0), 127, true, ch.setpoint);
  EXPECT_EQ(ch.change, Change::kNone);  // entered once
  // 5 s (250 ticks) later it descends, motors on while airborne ...
  ch = p.choose(0, command(100, 3.0), 126 + 250, true, ch.setpoint);
  EXPECT_TRUE(ch.setpoint.motors_on);
  EXPECT_DOUBLE_EQ(ch.setpoint.v_world.z(), -0.5);
  // ... and stops them on the ground.
  ch = p.choose(0, command(100, 3.0), 126 + 300, false, ch.setpoint);
  EXPECT_FALSE(ch.setpoint.motors_on);
  EXPECT_TRUE(p.active(0));
}

TEST(FailsafePolicy, ALostAgentsCommandIsNotFreshAndAFreshOneResumes) {
  FailsafePolicy p(2, kRules);
  VelocitySetpoint flying;
  flying.motors_on = true;
  auto ch = p.choose(1, command(100, 1.0, false), 101, true, flying);  // its agent is lost
  EXPECT_EQ(ch.change, Change::kEntered);
  EXPECT_FALSE(p.active(0));  // per drone
  ch = p.choose(1, command(110, 1.5), 110, true, ch.setpoint);
  EXPECT_EQ(ch.change, Change::kResumed);
  EXPECT_TRUE(ch.fresh);
  EXPECT_DOUBLE_EQ(ch.setpoint.v_world.x(), 1.5);
  EXPECT_FALSE(p.active(1));
}

TEST(FailsafePolicy, ACommandExactlyAtTheTimeoutIsStillFresh) {
  FailsafePolicy p(1, FailsafeRules{0.25, 0.5, 5.0});  // exact in binary: 2 ticks = 0.5 s
  EXPECT_TRUE(p.choose(0, command(10, 1.0), 12, true, {}).fresh);
  EXPECT_FALSE(p.choose(0, command(10, 1.0), 13, true, {}).fresh);
}
