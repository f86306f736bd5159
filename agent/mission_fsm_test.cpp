#include "agent/mission_fsm.hpp"

#include <gtest/gtest.h>

#include <vector>

using namespace ddswarm;
using namespace ddswarm::agent;
using Eigen::Vector3d;

namespace {

/// One drone on a perfect velocity plant: the FSM and the law close the loop.
struct Flight {
  explicit Flight(int id = 0, AgentConfig cfg = {}, SceneConfig scene = {})
      : cfg(cfg), fsm(id, cfg, scene) {}

  MissionOutput tick(double dt = 0.05) {
    stepped_at_s = o.sim_time_s;
    out = fsm.step(o);
    Vector3d v = Vector3d::Zero();
    if (out.motors_on) {
      LawInput in;
      in.p_world = o.p_world;
      set_mission(in, out);
      v = control_velocity(in, cfg);
    }
    o.p_world += dt * v;
    o.p_world.z() = std::max(o.p_world.z(), 0.0);
    o.v_world = v;
    o.on_ground = o.p_world.z() < 0.02;
    o.sim_time_s += dt;
    ++o.tick;
    return out;
  }
  /// Ticks until pred() or max_s of sim time; returns whether pred() held.
  template <class P>
  bool run_until(P pred, double max_s) {
    const double end = o.sim_time_s + max_s;
    while (o.sim_time_s < end) {
      tick();
      if (pred()) return true;
    }
    return false;
  }
  MissionAck send(MissionCommand c) {
    c.seq = ++seq;
    if (c.issuer.empty()) c.issuer = "gs";
    return fsm.apply(c, o);
  }

  AgentConfig cfg;
  MissionFsm fsm;
  Observation o;
  MissionOutput out;
  double stepped_at_s = 0;  // sim time of the observation the last step saw
  std::uint32_t seq = 0;
};

MissionCommand cmd(MissionType t) {
  MissionCommand c;
  c.type = t;
  return c;
}

MissionCommand move(Vector3d v, double duration_s) {
  MissionCommand c = cmd(MissionType::kMove);
  c.velocity = v;
  c.duration_s = duration_s;
  return c;
}

}  // namespace

TEST(MissionFsm, TakeoffHoldMoveHoldLandIdle) {
  Flight f;
  f.tick();
  EXPECT_EQ(f.out.phase, Phase::kIdle);
  EXPECT_FALSE(f.out.motors_on);
  EXPECT_FALSE(f.out.busy);

  MissionAck a = f.send(cmd(MissionType::kTakeoff));
  EXPECT_TRUE(a.accepted) << a.reason;
  EXPECT_EQ(a.phase, Phase::kTakeoff);
  f.tick();
  EXPECT_TRUE(f.out.motors_on);
  EXPECT_TRUE(f.out.busy);
  EXPECT_TRUE(f.run_until([&] { return f.fsm.phase() == Phase::kHold; }, 10));
  EXPECT_NEAR(f.o.p_world.z(), 2.0, f.cfg.altitude_tolerance_m);
  EXPECT_FALSE(f.out.busy) << "hold waits for the operator: the lockstep clock may pause";

  // A timed hold keeps the clock running for its duration, then releases it.
  MissionCommand timed = cmd(MissionType::kHold);
  timed.duration_s = 2.0;
  ASSERT_TRUE(f.send(timed).accepted);
  const double hold_start = f.o.sim_time_s;
  f.tick();
  EXPECT_TRUE(f.out.busy);
  EXPECT_TRUE(f.run_until([&] { return !f.out.busy; }, 10));
  EXPECT_NEAR(f.o.sim_time_s - hold_start, 2.0, 0.1);

  const double x0 = f.o.p_world.x();
  const double t0 = f.o.sim_time_s;
  ASSERT_TRUE(f.send(move({1, 0, 0}, 3.0)).accepted);
  EXPECT_TRUE(f.run_until([&] { return f.out.phase == Phase::kHold; }, 10));
  // Flips on the first tick at or after 3 s (ticks are 0.05 s apart).
  EXPECT_NEAR(f.stepped_at_s - t0, 3.025, 0.026) << "moves for 3 s of sim time";
  EXPECT_NEAR(f.o.p_world.x() - x0, 3.0, 0.051);
  EXPECT_EQ(f.out.mission_velocity, Vector3d::Zero());

  ASSERT_TRUE(f.send(cmd(MissionType::kLand)).accepted);
  f.tick();
  EXPECT_EQ(f.out.phase, Phase::kLanding);
  EXPECT_DOUBLE_EQ(f.out.mission_velocity.z(), -f.cfg.landing_speed_mps);
  EXPECT_FALSE(f.out.altitude_hold);
  EXPECT_TRUE(f.run_until([&] { return f.out.phase == Phase::kIdle; }, 10));
  EXPECT_FALSE(f.out.motors_on);
  EXPECT_FALSE(f.out.busy);
}

TEST(MissionFsm, RejectionsCarryReasonsAndChangeNothing) {
  Flight f;
  for (auto t : {MissionType::kMove, MissionType::kTask, MissionType::kHold}) {
    MissionCommand c = t == MissionType::kMove ? move({1, 0, 0}, 1) : cmd(t);
    MissionAck a = f.send(c);
    EXPECT_FALSE(a.accepted);
    EXPECT_EQ(a.reason, "not airborne") << to_string(t);
    EXPECT_EQ(a.phase, Phase::kIdle);
  }
  MissionCommand follow = cmd(MissionType::kFollowLeader);
  follow.leader_id = 0;
  EXPECT_EQ(f.send(follow).reason, "not airborne");
  EXPECT_EQ(f.send(cmd(static_cast<MissionType>(42))).reason, "unknown command type");
  EXPECT_EQ(f.send(cmd(MissionType::kNone)).reason, "unknown command type");
  EXPECT_TRUE(f.send(cmd(MissionType::kLand)).accepted) << "landing on the ground is a no-op";
  EXPECT_EQ(f.fsm.phase(), Phase::kIdle);

  ASSERT_TRUE(f.send(cmd(MissionType::kTakeoff)).accepted);
  EXPECT_EQ(f.send(move({1, 0, 0}, 1)).reason, "still taking off");
  ASSERT_TRUE(f.run_until([&] { return f.fsm.phase() == Phase::kHold; }, 10));
  EXPECT_EQ(f.send(cmd(MissionType::kTakeoff)).reason, "already airborne");
  EXPECT_EQ(f.send(move({1, 0, 0}, 0)).reason, "duration_s must be > 0");
  EXPECT_NE(f.send(move({5, 0, 0}, 1)).reason.find("exceeds agent.max_speed_mps"),
            std::string::npos);
  MissionCommand high = cmd(MissionType::kTakeoff);
  high.value = 500;
  EXPECT_NE(f.send(high).reason.find("above the world bounds"), std::string::npos);
  EXPECT_EQ(f.send(cmd(MissionType::kTeleop)).reason, "not following a leader");
  EXPECT_EQ(f.fsm.phase(), Phase::kHold);

  MissionCommand other = cmd(MissionType::kLand);
  other.target = 3;
  MissionAck a = f.send(other);
  EXPECT_FALSE(a.accepted);
  EXPECT_EQ(a.reason, "addressed to drone 3");
  EXPECT_EQ(f.fsm.phase(), Phase::kHold);
}

TEST(MissionFsm, RepeatedCommandIsAppliedOnce) {
  Flight f;
  f.send(cmd(MissionType::kTakeoff));
  ASSERT_TRUE(f.run_until([&] { return f.fsm.phase() == Phase::kHold; }, 10));
  MissionCommand m = move({0.5, 0, 0}, 2.0);
  m.seq = 100;
  m.issuer = "gs";
  const MissionAck first = f.fsm.apply(m, f.o);
  ASSERT_TRUE(first.accepted);
  const double t0 = f.o.sim_time_s;
  f.run_until([&] { return false; }, 1.5);
  // The ack was lost; the ground station repeats the command 1.5 s later.
  const MissionAck again = f.fsm.apply(m, f.o);
  EXPECT_EQ(again.tick, first.tick);
  EXPECT_EQ(again.accepted, first.accepted);
  EXPECT_EQ(again.phase, first.phase);
  // The move still ends 2 s after the first copy, not 2 s after the repeat.
  EXPECT_TRUE(f.run_until([&] { return f.out.phase == Phase::kHold; }, 5));
  EXPECT_NEAR(f.stepped_at_s - t0, 2.025, 0.026);

  // A different command under an old seq: its issuer restarted; it is applied.
  MissionCommand land = cmd(MissionType::kLand);
  land.seq = 1;
  land.issuer = "gs";
  EXPECT_TRUE(f.fsm.apply(land, f.o).accepted);
  EXPECT_EQ(f.fsm.phase(), Phase::kLanding);
}

TEST(MissionFsm, TaskFliesTowardTheGoalThenSwarmsPastTheFinish) {
  SceneConfig scene;
  scene.finish_a = {-20, 10};
  scene.finish_b = {20, 10};
  scene.goal_xy = {0, 15};
  Flight f(0, {}, scene);
  f.send(cmd(MissionType::kTakeoff));
  ASSERT_TRUE(f.run_until([&] { return f.fsm.phase() == Phase::kHold; }, 10));
  MissionAck a = f.send(cmd(MissionType::kTask));  // value 0: the configured 0.8 m/s
  ASSERT_TRUE(a.accepted) << a.reason;
  EXPECT_EQ(a.phase, Phase::kTask);
  f.tick();
  EXPECT_NEAR((f.out.mission_velocity - Vector3d(0, 0.8, 0)).norm(), 0.0, 1e-12);
  EXPECT_TRUE(f.out.busy);
  ASSERT_TRUE(f.run_until([&] { return f.out.phase == Phase::kSwarm; }, 30));
  EXPECT_GT(f.o.p_world.y(), 10.0 - 0.05);
  // Past the line it gathers around the goal (0, 15), no faster than the task speed.
  EXPECT_GT(f.out.mission_velocity.y(), 0.0);
  EXPECT_LE(f.out.mission_velocity.norm(), 0.8 + 1e-12);
  EXPECT_FALSE(f.out.busy) << "gathering: the server's task referee keeps the clock running";
  ASSERT_TRUE(f.run_until(
      [&] { return (f.o.p_world.head<2>() - Eigen::Vector2d(0, 15)).norm() < 0.5; }, 60))
      << "reaches the goal";
  EXPECT_LT(f.out.mission_velocity.norm(), 0.2) << "and slows to a stop there";

  MissionCommand fast = cmd(MissionType::kTask);
  fast.value = 1.2;
  f.send(cmd(MissionType::kHold));
  ASSERT_TRUE(f.send(fast).accepted);
  f.tick();  // already past the finish: gathers at once
  EXPECT_EQ(f.out.phase, Phase::kSwarm);
}

TEST(MissionFsm, SetDistanceTakesEffectWithoutRestart) {
  Flight f;
  MissionCommand d = cmd(MissionType::kSetDistance);
  d.value = 6;
  ASSERT_TRUE(f.send(d).accepted);
  EXPECT_EQ(f.fsm.inter_distance_m(), 6.0);
  EXPECT_EQ(f.tick().inter_distance_m, 6.0);
  EXPECT_EQ(f.fsm.phase(), Phase::kIdle);
  d.value = -1;
  EXPECT_EQ(f.send(d).reason, "distance must be > 0");
  EXPECT_EQ(f.fsm.inter_distance_m(), 6.0);

  // Two drones 6 m apart feel nothing at the new D_int and repel at the old one.
  LawInput in;
  in.p_world = {0, 0, 2};
  in.altitude_target_m = 2;
  const Vector3d peer(6, 0, 2);
  in.peers_world = std::span(&peer, 1);
  set_mission(in, f.out);
  in.swarm_enabled = true;
  EXPECT_NEAR(control_velocity(in, f.cfg).norm(), 0.0, 1e-12);
  in.inter_distance_m = 4;
  EXPECT_GT(control_velocity(in, f.cfg).x(), 0.0);
}

TEST(MissionFsm, LeaderFollowsTeleopWhichExpires) {
  Flight leader(2), follower(3);
  for (Flight* f : {&leader, &follower}) {
    f->send(cmd(MissionType::kTakeoff));
    ASSERT_TRUE(f->run_until([&] { return f->fsm.phase() == Phase::kHold; }, 10));
    MissionCommand c = cmd(MissionType::kFollowLeader);
    c.leader_id = 2;
    ASSERT_TRUE(f->send(c).accepted);
    MissionCommand t = cmd(MissionType::kTeleop);
    t.velocity = {0.5, 0.2, 0};
    ASSERT_TRUE(f->send(t).accepted);
  }
  leader.tick();
  follower.tick();
  EXPECT_EQ(leader.out.phase, Phase::kFollow);
  EXPECT_EQ(leader.out.mission_velocity, Vector3d(0.5, 0.2, 0));
  EXPECT_EQ(follower.out.mission_velocity, Vector3d::Zero()) << "followers swarm around";
  EXPECT_FALSE(leader.out.swarm_enabled) << "the pilot's drone is not pulled back by its followers";
  EXPECT_TRUE(leader.out.obstacle_avoidance_enabled) << "but still avoids obstacles";
  EXPECT_TRUE(follower.out.swarm_enabled);
  leader.run_until([&] { return false; }, 1.2);  // the link goes quiet
  EXPECT_EQ(leader.out.mission_velocity, Vector3d::Zero());
  EXPECT_EQ(leader.out.phase, Phase::kFollow);
}

TEST(MissionFsm, HoldAbortsALandingAtTheCurrentAltitude) {
  Flight f;
  f.send(cmd(MissionType::kTakeoff));
  ASSERT_TRUE(f.run_until([&] { return f.fsm.phase() == Phase::kHold; }, 10));
  f.send(cmd(MissionType::kLand));
  f.run_until([&] { return false; }, 1.0);
  const double z = f.o.p_world.z();
  ASSERT_LT(z, 1.8);
  ASSERT_TRUE(f.send(cmd(MissionType::kHold)).accepted);
  f.tick();
  EXPECT_EQ(f.out.phase, Phase::kHold);
  EXPECT_NEAR(f.out.altitude_target_m, z, 1e-9);
  EXPECT_TRUE(f.out.altitude_hold);
}

TEST(MissionFsm, VerticalMoveCarriesTheCruiseAltitude) {
  Flight f;
  f.send(cmd(MissionType::kTakeoff));
  ASSERT_TRUE(f.run_until([&] { return f.fsm.phase() == Phase::kHold; }, 10));
  ASSERT_TRUE(f.send(move({0, 0, 0.5}, 2.0)).accepted);
  ASSERT_TRUE(f.run_until([&] { return f.out.phase == Phase::kHold; }, 5));
  EXPECT_NEAR(f.out.altitude_target_m, 3.0, 0.03);
  f.run_until([&] { return false; }, 5);
  EXPECT_NEAR(f.o.p_world.z(), 3.0, 0.03) << "holds the new altitude";
}

TEST(MissionFsm, ConstructorValidates) {
  AgentConfig bad;
  bad.inter_distance_m = 0;
  EXPECT_THROW(MissionFsm(0, bad, SceneConfig{}), FieldError);
  EXPECT_THROW(MissionFsm(-1, AgentConfig{}, SceneConfig{}), std::invalid_argument);
}

TEST(MissionFsm, ARejoiningAgentLandedByFailsafeClimbsThenResumesTheTask) {
  // The swarm took off at t=1 s and started the task at t=5 s; this agent
  // restarts at t=40 s, its drone on the ground (the server's failsafe landed it).
  Flight f;
  f.o.sim_time_s = 40.0;
  MissionCommand takeoff = cmd(MissionType::kTakeoff);
  takeoff.seq = 1;
  takeoff.issuer = "gs";
  MissionCommand task = cmd(MissionType::kTask);
  task.seq = 2;
  task.issuer = "gs";
  task.value = 0.8;
  EXPECT_TRUE(f.fsm.resume(takeoff, 1.0, f.o).accepted);
  MissionAck a = f.fsm.resume(task, 5.0, f.o);
  EXPECT_TRUE(a.accepted) << a.reason;
  EXPECT_EQ(a.phase, Phase::kTakeoff) << "climbs first";
  f.tick();
  EXPECT_TRUE(f.out.busy) << "the lockstep clock must run while it climbs";
  EXPECT_TRUE(f.run_until([&] { return f.fsm.phase() == Phase::kTask; }, 10));
  EXPECT_NEAR(f.o.p_world.z(), 2.0, f.cfg.altitude_tolerance_m);
  f.tick();
  EXPECT_GT(f.out.mission_velocity.norm(), 0.7) << "flies the task again";
  // The ground station's repeat of the task is recognised, not re-applied.
  EXPECT_TRUE(f.fsm.apply(task, f.o).accepted);
  EXPECT_EQ(f.fsm.phase(), Phase::kTask);
}

TEST(MissionFsm, ARejoiningAgentStillHoveringResumesAtOnceAndAnEndedMoveIsAHold) {
  Flight f;
  f.o.p_world = {0, 0, 2.0};
  f.o.on_ground = false;
  f.o.sim_time_s = 30.0;
  MissionCommand takeoff = cmd(MissionType::kTakeoff);
  takeoff.seq = 1;
  takeoff.issuer = "gs";
  MissionCommand mv = move({1, 0, 0}, 5.0);
  mv.seq = 2;
  mv.issuer = "gs";
  ASSERT_TRUE(f.fsm.resume(takeoff, 1.0, f.o).accepted);
  ASSERT_TRUE(f.fsm.resume(mv, 10.0, f.o).accepted);  // ended at t=15 s
  f.tick();
  f.tick();
  EXPECT_EQ(f.out.phase, Phase::kHold);
  EXPECT_EQ(f.out.mission_velocity, Vector3d::Zero());

  Flight g;
  g.o = f.o;
  ASSERT_TRUE(g.fsm.resume(takeoff, 1.0, g.o).accepted);
  ASSERT_TRUE(g.fsm.resume(mv, 28.0, g.o).accepted);  // 3 s of it left
  g.tick();
  g.tick();
  EXPECT_EQ(g.out.phase, Phase::kMove);
  EXPECT_TRUE(g.run_until([&] { return g.out.phase == Phase::kHold; }, 10));
  EXPECT_NEAR(g.stepped_at_s, 33.0, 0.06) << "the move ends when the swarm's ends";
}

TEST(MissionFsm, ResumeAfterALandStaysDownAndRejectsFlyingCommands) {
  Flight f;
  f.o.sim_time_s = 50.0;
  MissionCommand takeoff = cmd(MissionType::kTakeoff);
  takeoff.seq = 1;
  takeoff.issuer = "gs";
  MissionCommand land = cmd(MissionType::kLand);
  land.seq = 2;
  land.issuer = "gs";
  ASSERT_TRUE(f.fsm.resume(takeoff, 1.0, f.o).accepted);
  ASSERT_TRUE(f.fsm.resume(land, 20.0, f.o).accepted);
  EXPECT_EQ(f.fsm.phase(), Phase::kIdle);
  MissionCommand task = cmd(MissionType::kTask);
  task.seq = 3;
  task.issuer = "gs";
  EXPECT_EQ(f.fsm.resume(task, 30.0, f.o).reason, "not airborne");
}
