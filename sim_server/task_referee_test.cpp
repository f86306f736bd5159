#include "sim_server/task_referee.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace ddswarm;
using namespace ddswarm::sim;

namespace {
SceneConfig course() {
  SceneConfig s;
  s.finish_a = {-20, 50};
  s.finish_b = {20, 50};
  s.goal_xy = {0, 60};
  s.cylinders.push_back({{0, 20}, 1.0, 10.0});
  return s;
}

/// One tick of drones 0..n-1 hovering (zero velocity) at p.
bool update(TaskReferee& r, double t, const std::vector<Eigen::Vector3d>& p, double timeout_s) {
  std::vector<int> ids(p.size());
  for (std::size_t k = 0; k < p.size(); ++k) ids[k] = static_cast<int>(k);
  return r.update(t, p, std::vector<Eigen::Vector3d>(p.size(), Eigen::Vector3d::Zero()), ids,
                  timeout_s);
}
}  // namespace

TEST(TaskReferee, CompletesOnlyWhenAllPastFinishAndWithinEpsilon) {
  SceneConfig s = course();
  TaskReferee r(s);
  r.start(7, 10.0, 5.0, 0.8, 3);
  std::vector<Eigen::Vector3d> p = {{0, 51, 2}, {2, 51, 2}, {0, 49, 2}};
  EXPECT_FALSE(update(r, 20.0, p, 600));  // one drone short of the line
  EXPECT_EQ(r.report().past_finish, 2);
  p[2] = {0, 60, 2};  // past, but 9 m away: swarm condition fails
  EXPECT_FALSE(update(r, 21.0, p, 600));
  p[2] = {1, 53, 2};
  EXPECT_TRUE(update(r, 22.0, p, 600));
  EXPECT_EQ(r.report().phase, TaskPhase::kComplete);
  EXPECT_DOUBLE_EQ(r.report().elapsed_s, 12.0);
  EXPECT_NEAR(r.report().min_inter_drone_m, 2.0, 1e-9);  // drones 0 and 1, 2 m apart throughout
}

TEST(TaskReferee, TracksMinimumsAndCollisionsOnlyWhileRunning) {
  SceneConfig s = course();
  TaskReferee r(s);
  r.count_collision(0);  // before the task: not counted
  r.start(1, 0.0, 5.0, 0.8, 2);
  update(r, 1.0, {{0, 17.5, 2}, {0, 15, 2}}, 600);
  EXPECT_NEAR(r.report().min_clearance_m, 1.5, 1e-9);
  EXPECT_NEAR(r.report().min_inter_drone_m, 2.5, 1e-9);
  r.count_collision(0);
  r.count_collision(1);
  r.count_collision(2);
  EXPECT_EQ(r.report().collisions_obstacle, 1u);
  EXPECT_EQ(r.report().collisions_drone, 1u);
  EXPECT_EQ(r.report().collisions_ground, 1u);
}

TEST(TaskReferee, FailsOnTimeoutOrAbort) {
  SceneConfig s = course();
  TaskReferee r(s);
  r.start(1, 0.0, 5.0, 0.8, 1);
  EXPECT_TRUE(update(r, 601.0, {{0, 0, 2}}, 600));
  EXPECT_EQ(r.report().phase, TaskPhase::kFailed);
  EXPECT_NE(r.report().reason.find("timeout"), std::string::npos);
  r.start(2, 0.0, 5.0, 0.8, 1);
  r.fail("aborted by land command");
  EXPECT_EQ(r.report().phase, TaskPhase::kFailed);
  EXPECT_FALSE(r.running());
}

TEST(TaskReferee, ReportsDronesLostDuringTheTaskOnceAndOnlyWhileRunning) {
  SceneConfig s = course();
  TaskReferee r(s);
  r.note_lost(4);  // before the task: not this task's loss
  r.start(1, 0.0, 5.0, 0.8, 6);
  r.note_lost(3);
  r.note_lost(1);
  r.note_lost(3);
  EXPECT_EQ(r.report().lost_drones, (std::vector<int>{1, 3}));
  r.fail("aborted");
  r.note_lost(5);
  EXPECT_EQ(r.report().lost_drones, (std::vector<int>{1, 3}));
  r.start(2, 1.0, 5.0, 0.8, 6);
  EXPECT_TRUE(r.report().lost_drones.empty());
}

TEST(TaskReferee, GathersTheSwarmMetricsOfEveryTickOfTheTask) {
  SceneConfig s = course();
  SwarmMetricsOptions o;
  o.range_m = 3.0;
  o.near_miss_m = 1.0;
  TaskReferee r(s, o);
  const std::vector<Eigen::Vector3d> north(3, Eigen::Vector3d(0, 0.8, 0));
  // Before the task: not this task's ticks.
  r.update(0.5, {{0, 0, 2}, {0.5, 0, 2}, {9, 0, 2}}, north, {0, 1, 2}, 600);
  r.start(1, 1.0, 5.0, 0.8, 3);
  EXPECT_TRUE(std::isnan(r.report().metrics.order_mean));
  // Tick 1: aligned northward, a line 2 m apart (connected at 3 m).
  r.update(1.0, {{0, 0, 2}, {2, 0, 2}, {4, 0, 2}}, north, {0, 1, 2}, 600);
  EXPECT_DOUBLE_EQ(r.report().order, 1.0);
  EXPECT_EQ(r.report().components, 1);
  EXPECT_NEAR(r.report().lambda2, 1.0, 1e-9);  // P_3
  // Tick 2: drone 2 turns back and leaves the graph; drones 0 and 1 come within 0.5 m.
  r.update(1.02, {{0, 0, 2}, {0.5, 0, 2}, {9, 0, 2}}, {{0, 0.8, 0}, {0, 0.8, 0}, {0, -1.6, 0}},
           {0, 1, 2}, 600);
  EXPECT_NEAR(r.report().order, -1.0 / 3.0, 1e-12);
  EXPECT_EQ(r.report().components, 2);
  EXPECT_EQ(r.report().lambda2, 0.0);
  // Tick 3: drone 2 lost (the caller leaves it out); 0 and 1 still close: the same near miss.
  r.update(1.04, {{0, 0, 2}, {0.6, 0, 2}}, {{0, 0.8, 0}, {0, 0.8, 0}}, {0, 1}, 600);
  const SwarmTaskMetrics& m = r.report().metrics;
  EXPECT_NEAR(m.order_mean, (1.0 - 1.0 / 3.0 + 1.0) / 3, 1e-12);
  EXPECT_NEAR(m.order_min, -1.0 / 3.0, 1e-12);
  EXPECT_NEAR(m.speed_mean_mps, (0.8 + (0.8 + 0.8 + 1.6) / 3 + 0.8) / 3, 1e-12);
  EXPECT_EQ(m.near_misses, 1u);
  EXPECT_EQ(m.components_max, 2);
  EXPECT_EQ(m.lambda2_min, 0.0);
  EXPECT_EQ(m.range_m, 3.0);
  // The thesis's own numbers come from the same ticks.
  EXPECT_NEAR(r.report().min_inter_drone_m, 0.5, 1e-12);
  EXPECT_NEAR(r.report().max_pair_distance_m, 0.6, 1e-12);
  // After the task ends nothing more is gathered; a new task starts afresh.
  r.fail("aborted");
  r.update(2.0, {{0, 0, 2}, {0.1, 0, 2}}, {{0, 0.8, 0}, {0, -0.8, 0}}, {0, 1}, 600);
  EXPECT_EQ(r.report().metrics.near_misses, 1u);
  EXPECT_NEAR(r.report().metrics.order_min, -1.0 / 3.0, 1e-12);
  r.start(2, 3.0, 5.0, 0.8, 2);
  EXPECT_EQ(r.report().metrics.near_misses, 0u);
  EXPECT_EQ(r.report().metrics.components_max, 0);
}

TEST(TaskReferee, AMissionCommandStartsOrAbortsTheTask) {
  SceneConfig s = course();
  TaskReferee r(s);
  // A task command without epsilon: 2 D_int + 1 of the distance in force.
  r.on_mission(MissionType::kTask, 7, 0.8, 0.0, 3.0, 12.0, 6);
  ASSERT_TRUE(r.running());
  EXPECT_EQ(r.report().seq, 7u);
  EXPECT_DOUBLE_EQ(r.report().epsilon_m, default_epsilon(3.0));
  EXPECT_DOUBLE_EQ(r.report().start_sim_time_s, 12.0);
  EXPECT_DOUBLE_EQ(r.report().speed_mps, 0.8);
  EXPECT_EQ(r.report().drones, 6);
  // Takeoff, hold or a new distance leave it running.
  r.on_mission(MissionType::kHold, 8, 0.0, 0.0, 3.0, 13.0, 6);
  r.on_mission(MissionType::kSetDistance, 9, 5.0, 0.0, 3.0, 13.0, 6);
  EXPECT_TRUE(r.running());
  r.on_mission(MissionType::kLand, 10, 0.0, 0.0, 3.0, 14.0, 6);
  EXPECT_EQ(r.report().phase, TaskPhase::kFailed);
  EXPECT_EQ(r.report().reason,
            std::string("aborted by ") + to_string(MissionType::kLand) + " command");
  // Another task command starts a new task (epsilon given) ...
  r.on_mission(MissionType::kTask, 11, 1.0, 9.5, 3.0, 15.0, 6);
  EXPECT_TRUE(r.running());
  EXPECT_DOUBLE_EQ(r.report().epsilon_m, 9.5);
  // ... and a task command while one runs aborts it, then starts the new one.
  r.on_mission(MissionType::kTask, 12, 1.0, 9.5, 3.0, 16.0, 6);
  EXPECT_TRUE(r.running());
  EXPECT_EQ(r.report().seq, 12u);
}
