#include "ground_station/menu.hpp"

#include <gtest/gtest.h>

#include <sstream>
#include <stdexcept>
#include <vector>

namespace ddswarm::gs {
namespace {

std::string fmt(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

/// Six drones holding in lockstep at 12.5 s, D_int 4 m.
SwarmStatus hovering() {
  SwarmStatus s;
  s.sim_time_s = 12.5;
  s.real_time_factor = 1.0;
  s.drones_online = s.drones_total = s.airborne = 6;
  s.mode = "lockstep";
  s.task_phase = "hold";
  s.d_int_m = 4.0;
  return s;
}

/// Records every command as one line, e.g. "move 0.4 1.2 0 30".
class FakeCommander : public Commander {
 public:
  std::vector<std::string> calls;
  SwarmStatus state = hovering();
  CommandResult answer{true, "6/6 acknowledged"};
  CommandResult task_answer{true, "6/6 acknowledged"};
  bool throw_on_command = false;
  bool throw_on_status = false;

  CommandResult takeoff(double a) override { return record("takeoff " + fmt(a)); }
  CommandResult move(const Eigen::Vector3d& v, double t) override {
    return record("move " + vec(v) + " " + fmt(t));
  }
  CommandResult set_distance(double d) override {
    auto r = record("set_distance " + fmt(d));
    state.d_int_m = d;
    return r;
  }
  CommandResult land() override { return record("land"); }
  CommandResult follow_leader(int id) override { return record("follow " + std::to_string(id)); }
  CommandResult teleop(const Eigen::Vector3d& v) override { return record("teleop " + vec(v)); }
  CommandResult hold() override { return record("hold"); }
  CommandResult task(double speed, double eps) override {
    record("task " + fmt(speed) + " " + fmt(eps));
    return task_answer;
  }
  std::string wait_task(std::function<void(const std::string&)> on_progress) override {
    calls.push_back("wait_task");
    on_progress("3/6 past the finish line");
    on_progress("6/6 past the finish line");
    return "task completed in 82.6 s, 0 collisions";
  }
  SwarmStatus status() override {
    if (throw_on_status) throw std::runtime_error("no server");
    return state;
  }

 private:
  static std::string vec(const Eigen::Vector3d& v) {
    return fmt(v.x()) + " " + fmt(v.y()) + " " + fmt(v.z());
  }
  CommandResult record(const std::string& call) {
    calls.push_back(call);
    if (throw_on_command) throw std::runtime_error("DDS writer closed");
    return answer;
  }
};

struct Session {
  int rc;
  std::string out;
  std::vector<std::string> calls;
};

Session run(const std::string& input, FakeCommander fake = {}, MenuOptions opt = {}) {
  std::istringstream in(input);
  std::ostringstream out;
  LineReader reader(in, out);
  int rc = run_menu(fake, reader, out, opt);
  return {rc, out.str(), fake.calls};
}

using Calls = std::vector<std::string>;

bool contains(const std::string& haystack, const std::string& needle) {
  return haystack.find(needle) != std::string::npos;
}

int count(const std::string& haystack, const std::string& needle) {
  int n = 0;
  for (auto p = haystack.find(needle); p != std::string::npos; p = haystack.find(needle, p + 1))
    ++n;
  return n;
}

TEST(Menu, ShowsThesisMenuWithStatusAndQuits) {
  auto s = run("0\n");
  EXPECT_EQ(s.rc, 0);
  EXPECT_TRUE(s.calls.empty());
  EXPECT_TRUE(contains(s.out,
                       "Please choose an option:\n1: Takeoff\n2: Move swarm by velocity and time\n"
                       "3: Change distance between drones\n4: Land\n5: Follow the leader\n"
                       "6: Task\n0: Quit\n"));
  EXPECT_TRUE(contains(s.out,
                       "[sim 12.5 s | x1.00 real time | drones 6/6 online | 6 airborne | "
                       "0 collisions | lockstep | phase hold | D_int 4 m]"));
  EXPECT_LT(s.out.find("[sim"), s.out.find("Please choose"));  // status before the menu
  EXPECT_TRUE(contains(s.out, "6 drone(s) still airborne"));
}

TEST(Menu, StatusLinePrintedBeforeEveryMenu) {
  auto s = run("4\n4\n0\n");
  EXPECT_EQ(count(s.out, "[sim "), 3);
  EXPECT_EQ(count(s.out, "Please choose an option:"), 3);
}

TEST(Menu, TakeoffUsesDefaultAltitudeOrOneGivenOnTheLine) {
  auto s = run("1\n1 5\n0\n");
  EXPECT_EQ(s.rc, 0);
  EXPECT_EQ(s.calls, (Calls{"takeoff 0", "takeoff 5"}));
  EXPECT_EQ(count(s.out, "Takeoff: 6/6 acknowledged"), 2);
}

TEST(Menu, MoveAsInThesisFig10a) {
  auto s = run("2\n1.2\n0.4\n0\n30\n0\n");
  EXPECT_EQ(s.rc, 0);
  // ENU: east = x, north = y, up = z.
  EXPECT_EQ(s.calls, (Calls{"move 0.4 1.2 0 30"}));
  EXPECT_TRUE(contains(s.out,
                       "Velocity in North direction: 1.2\nVelocity in East direction: 0.4\n"
                       "Velocity in Up direction: 0\nFor time in seconds: 30\n"));
  EXPECT_TRUE(contains(s.out, "Move: 6/6 acknowledged"));
}

TEST(Menu, MoveAnswersMayFollowTheOption) {
  auto s = run("2 1.2 0.4 0 30\n0\n");
  EXPECT_EQ(s.calls, (Calls{"move 0.4 1.2 0 30"}));
  EXPECT_TRUE(contains(s.out, "For time in seconds: 30\n"));
}

TEST(Menu, MoveReasksBadNumbersWithAReason) {
  auto s = run("2\nabc\n+1.2\n+-1\n-0.4\nNaN\n0\n-5\n1e308\n30\n0\n");
  EXPECT_EQ(s.rc, 0);
  EXPECT_EQ(s.calls, (Calls{"move -0.4 1.2 0 30"}));
  EXPECT_TRUE(contains(s.out, "'abc' is not a number. Try again"));
  EXPECT_TRUE(contains(s.out, "'+-1' is not a number. Try again"));
  EXPECT_TRUE(contains(s.out, "NaN: must be a finite number. Try again"));
  EXPECT_TRUE(contains(s.out, "-5: must be greater than 0 s. Try again"));
  EXPECT_TRUE(contains(s.out, "1e308: must be at most 3600 s. Try again"));
}

TEST(Menu, MoveRejectsSpeedAboveLimitAndInfinity) {
  MenuOptions opt;
  opt.max_speed_mps = 5;
  auto s = run("2\n6\ninf\n1e400\n0\n", {}, opt);
  EXPECT_TRUE(s.calls.empty());
  EXPECT_TRUE(contains(s.out, "6: must be at most 5 m/s"));
  EXPECT_TRUE(contains(s.out, "inf: must be a finite number"));
  EXPECT_TRUE(contains(s.out, "1e400: number out of range. Too many invalid entries"));
  EXPECT_EQ(s.rc, 0);
}

TEST(Menu, GivesUpAfterMaxAttemptsAndReturnsToTheMenu) {
  auto s = run("2\nx\ny\nz\n4\n0\n");
  EXPECT_EQ(s.rc, 0);
  EXPECT_EQ(s.calls, (Calls{"land"}));  // "4" after giving up is a menu choice again
  EXPECT_EQ(count(s.out, "Try again"), 2);
  EXPECT_TRUE(contains(s.out, "'z' is not a number. Too many invalid entries; back to the menu."));
}

TEST(Menu, QCancelsAQuestion) {
  auto s = run("2\n1\nq\n0\n");
  EXPECT_TRUE(s.calls.empty());
  EXPECT_TRUE(contains(s.out, "Cancelled."));
}

TEST(Menu, ChangeDistanceAsInThesisFig10b) {
  auto s = run("3\n6\n3\n0\n");
  EXPECT_EQ(s.calls, (Calls{"set_distance 6"}));
  EXPECT_TRUE(contains(s.out, "Current distance between drones: 4\nNew distance: 6\n"));
  EXPECT_TRUE(contains(s.out, "Current distance between drones: 6\n"));
  EXPECT_TRUE(contains(s.out, "Change distance: 6/6 acknowledged"));
}

TEST(Menu, ChangeDistanceRejectsNegativeZeroAndHuge) {
  auto s = run("3\n-1\n0\n1e308\n0\n");
  EXPECT_TRUE(s.calls.empty());
  EXPECT_TRUE(contains(s.out, "-1: must be at least 0.5 m"));
  EXPECT_TRUE(contains(s.out, "0: must be at least 0.5 m"));
  EXPECT_TRUE(contains(s.out, "1e308: must be at most 50 m. Too many invalid entries"));
  EXPECT_EQ(s.rc, 0);
}

TEST(Menu, LandPrintsAFailedResult) {
  FakeCommander fake;
  fake.answer = {false, "no ack from drones 3, 5"};
  auto s = run("4\n0\n", fake);
  EXPECT_EQ(s.calls, (Calls{"land"}));
  EXPECT_TRUE(contains(s.out, "Land FAILED: no ack from drones 3, 5"));
}

TEST(Menu, FollowTheLeaderTeleopsThenHolds) {
  auto s = run("5\n2\nh\nw\nwd\n0.5 1 0\n\nrf\nx\nq\n0\n");
  EXPECT_EQ(s.rc, 0);
  EXPECT_EQ(s.calls, (Calls{"follow 2", "teleop 0 1 0", "teleop 1 1 0", "teleop 0.5 1 0",
                            "teleop 0 0 0", "teleop 0 0 0", "hold"}));
  EXPECT_TRUE(contains(s.out, "Leader drone id (0-5): 2"));
  EXPECT_TRUE(contains(s.out, "w/s: north/south"));
  EXPECT_TRUE(contains(s.out, "q: leave"));
  EXPECT_TRUE(contains(s.out, "Leader velocity E 1 N 1 U 0 m/s: 6/6 acknowledged"));
  EXPECT_TRUE(contains(s.out, "Hold: 6/6 acknowledged"));
}

TEST(Menu, FollowRejectsUnknownLeaderIds) {
  auto s = run("5\n6\n-1\n1.5\n0\n");
  EXPECT_TRUE(s.calls.empty());
  EXPECT_TRUE(contains(s.out, "6: must be between 0 and 5"));
  EXPECT_TRUE(contains(s.out, "-1: must be between 0 and 5"));
  EXPECT_TRUE(contains(s.out, "'1.5' is not a whole number. Too many invalid entries"));
}

TEST(Menu, TeleopLeavesAfterRepeatedBadInputAndHolds) {
  auto s = run("5\n0\nz\n1 2\n99 0 0\n0\n");
  EXPECT_EQ(s.rc, 0);
  EXPECT_EQ(s.calls, (Calls{"follow 0", "hold"}));
  EXPECT_TRUE(contains(s.out, "unknown key 'z'"));
  EXPECT_TRUE(contains(s.out, "99: must be at most 10 m/s. Too many invalid entries; leaving"));
}

TEST(Menu, FailedFollowReturnsTheSwarmToHold) {
  FakeCommander fake;
  fake.answer = {false, "rejected by 2: not airborne"};
  auto s = run("5\n1\n0\n", fake);
  EXPECT_EQ(s.calls, (Calls{"follow 1", "hold"}));
  EXPECT_TRUE(contains(s.out, "Follow the leader FAILED: rejected by 2: not airborne"));
  EXPECT_FALSE(contains(s.out, "teleop>"));
}

TEST(Menu, EndOfInputDuringTeleopHoldsAndExits) {
  auto s = run("5\n1\nw\n");
  EXPECT_EQ(s.rc, 0);
  EXPECT_EQ(s.calls, (Calls{"follow 1", "teleop 0 1 0", "hold"}));
  EXPECT_TRUE(contains(s.out, "End of input"));
}

TEST(Menu, TaskWithDefaultSpeedShowsProgressAndResult) {
  auto s = run("6\n\n0\n");
  EXPECT_EQ(s.calls, (Calls{"task 0.8 0", "wait_task"}));
  EXPECT_TRUE(contains(s.out, "Task speed in m/s [0.8]: \n"));
  EXPECT_TRUE(contains(s.out, "  3/6 past the finish line\n  6/6 past the finish line\n"));
  EXPECT_TRUE(contains(s.out, "Task result: task completed in 82.6 s, 0 collisions"));
}

TEST(Menu, TaskWithGivenSpeedAndRejectedTask) {
  auto s = run("6\n-1\n1.2\n0\n");
  EXPECT_EQ(s.calls, (Calls{"task 1.2 0", "wait_task"}));
  EXPECT_TRUE(contains(s.out, "-1: must be greater than 0 m/s"));

  FakeCommander fake;
  fake.task_answer = {false, "rejected by 0: not airborne"};
  s = run("6\n1.2\n0\n", fake);
  EXPECT_EQ(s.calls, (Calls{"task 1.2 0"}));  // no waiting on a task that never started
  EXPECT_TRUE(contains(s.out, "Task FAILED: rejected by 0: not airborne"));
}

TEST(Menu, CommanderExceptionsAreReportedAndTheMenuGoesOn) {
  FakeCommander fake;
  fake.throw_on_command = true;
  fake.throw_on_status = true;
  auto s = run("4\n3\n5\n0\n", fake);
  EXPECT_EQ(s.rc, 0);
  EXPECT_EQ(s.calls, (Calls{"land", "set_distance 5"}));
  EXPECT_TRUE(contains(s.out, "Land FAILED: error: DDS writer closed"));
  EXPECT_TRUE(contains(s.out, "[status unavailable: no server]"));
  EXPECT_TRUE(contains(s.out, "Current distance between drones: unknown (no server)"));
}

TEST(Menu, UnknownOptionsAndBlankLines) {
  auto s = run("\n7\nabc\n-1\nh\n0\n");
  EXPECT_EQ(s.rc, 0);
  EXPECT_TRUE(s.calls.empty());
  EXPECT_TRUE(contains(s.out, "Unknown option '7': choose 0-6"));
  EXPECT_TRUE(contains(s.out, "Unknown option 'abc'"));
  EXPECT_TRUE(contains(s.out, "Unknown option '-1'"));
  EXPECT_TRUE(contains(s.out, "`q` at a question"));
}

TEST(Menu, WindowsLineEndingsAreAccepted) {
  auto s = run("2\r\n1.2\r\n0.4\r\n0\r\n30\r\n0\r\n");
  EXPECT_EQ(s.calls, (Calls{"move 0.4 1.2 0 30"}));
}

// A session touching every prompt, cut after every line and mid-line: the
// menu must always return 0 and say so, never crash or spin.
TEST(Menu, EndOfInputAtEveryPromptExitsCleanly) {
  const std::vector<std::string> lines = {"1", "2", "1", "0", "x", "0", "10", "3", "5", "5",
                                          "1", "w", "q", "6", "",  "6", "1",  "4", "0"};
  std::string full;
  for (const auto& l : lines) full += l + "\n";
  auto s = run(full);
  ASSERT_EQ(s.rc, 0);
  ASSERT_FALSE(contains(s.out, "End of input"));  // the full session quits with 0
  for (std::size_t cut = 0; cut + 1 < lines.size(); ++cut) {
    std::string prefix;
    for (std::size_t i = 0; i < cut; ++i) prefix += lines[i] + "\n";
    for (const std::string& input : {prefix, prefix + lines[cut]}) {
      s = run(input);
      EXPECT_EQ(s.rc, 0) << "input: " << input;
      EXPECT_TRUE(contains(s.out, "End of input")) << "input: " << input;
    }
  }
}

TEST(Menu, InterruptLeavesTeleopThroughHold) {
  std::istringstream in("5\n1\nw\nd\n");
  std::ostringstream out;
  LineReader reader(in, out);
  int reads = 0;
  reader.set_interrupt([&] { return ++reads > 3; });  // "Ctrl-C" before the 4th line
  FakeCommander fake;
  EXPECT_EQ(run_menu(fake, reader, out), 0);
  EXPECT_EQ(fake.calls, (Calls{"follow 1", "teleop 0 1 0", "hold"}));
  EXPECT_TRUE(contains(out.str(), "Interrupted: leaving the ground station."));
}

TEST(Menu, RejectsBadOptions) {
  MenuOptions opt;
  opt.max_attempts = 0;
  std::istringstream in("0\n");
  std::ostringstream out;
  LineReader reader(in, out);
  FakeCommander fake;
  EXPECT_THROW(run_menu(fake, reader, out, opt), FieldError);
}

TEST(Status, RejectionsAreCountedByReason) {
  SwarmStatus s;
  EXPECT_EQ(format_rejections(s), "rejected samples: unknown (no server or agent heard)");
  s.rejected = {{"non-finite", 3}, {"absurd", 0}, {"mission", 2}, {"agents", 1}};
  EXPECT_EQ(format_rejections(s),
            "rejected samples: 6 (non-finite 3, absurd 0, mission 2, agents 1)");
}

TEST(Status, CommandsAppliedAndLate) {
  SwarmStatus s;
  EXPECT_EQ(format_commands(s), "");  // no server heard
  s.commands_applied = 1200;
  s.commands_late = 3;
  EXPECT_EQ(format_commands(s), "commands: 1200 applied, 3 late (answered after their step)");
  s.lockstep_resends = 2;  // lockstep: a sample lost, the tick went out again
  EXPECT_EQ(format_commands(s),
            "commands: 1200 applied, 3 late (answered after their step); 2 ticks published again "
            "(answers missing)");
}

}  // namespace
}  // namespace ddswarm::gs
