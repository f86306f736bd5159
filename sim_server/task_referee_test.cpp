#include "sim_server/task_referee.hpp"

#include <gtest/gtest.h>

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
}  // namespace

TEST(TaskReferee, CompletesOnlyWhenAllPastFinishAndWithinEpsilon) {
  SceneConfig s = course();
  TaskReferee r(s);
  r.start(7, 10.0, 5.0, 0.8, 3);
  std::vector<Eigen::Vector3d> p = {{0, 51, 2}, {2, 51, 2}, {0, 49, 2}};
  EXPECT_FALSE(r.update(20.0, p, 600));  // one drone short of the line
  EXPECT_EQ(r.report().past_finish, 2);
  p[2] = {0, 60, 2};  // past, but 9 m away: swarm condition fails
  EXPECT_FALSE(r.update(21.0, p, 600));
  p[2] = {1, 53, 2};
  EXPECT_TRUE(r.update(22.0, p, 600));
  EXPECT_EQ(r.report().phase, TaskPhase::kComplete);
  EXPECT_DOUBLE_EQ(r.report().elapsed_s, 12.0);
  EXPECT_NEAR(r.report().min_inter_drone_m, 2.0, 1e-9);  // drones 0 and 1, 2 m apart throughout
}

TEST(TaskReferee, TracksMinimumsAndCollisionsOnlyWhileRunning) {
  SceneConfig s = course();
  TaskReferee r(s);
  r.count_collision(0);  // before the task: not counted
  r.start(1, 0.0, 5.0, 0.8, 2);
  r.update(1.0, {{0, 17.5, 2}, {0, 15, 2}}, 600);
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
  EXPECT_TRUE(r.update(601.0, {{0, 0, 2}}, 600));
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
