// The console after a stop longer than its DDS lease: the next command goes
// through a new participant, and the console says why; without such a stop
// it keeps the one it has.
#include "ground_station/rejoining_commander.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <utility>

namespace ddswarm::gs {
namespace {

// Answers hold() with which participant it stands for.
class Numbered : public Commander {
 public:
  explicit Numbered(int n) : n_(n) {}
  CommandResult takeoff(double) override { return said(); }
  CommandResult move(const Eigen::Vector3d&, double) override { return said(); }
  CommandResult set_distance(double) override { return said(); }
  CommandResult land() override { return said(); }
  CommandResult follow_leader(int) override { return said(); }
  CommandResult teleop(const Eigen::Vector3d&) override { return said(); }
  CommandResult hold() override { return said(); }
  CommandResult task(double, double) override { return said(); }
  std::string wait_task(std::function<void(const std::string&)>) override { return said().message; }
  SwarmStatus status() override { return {}; }

 private:
  CommandResult said() const { return {true, "participant " + std::to_string(n_)}; }
  int n_;
};

struct Rig {
  std::atomic<double> now{100.0};
  int made = 1;
  bool fail_next_join = false;
  std::ostringstream log;
  RejoiningCommander gs{std::make_unique<Numbered>(1),
                        [this]() -> std::unique_ptr<Commander> {
                          if (std::exchange(fail_next_join, false))
                            throw std::runtime_error("no DDS");
                          return std::make_unique<Numbered>(++made);
                        },
                        3.0,
                        log,
                        [this] { return now.load(); },
                        0.002};

  // Lets the watch turn a few times at the clock's present reading.
  void settle() { std::this_thread::sleep_for(std::chrono::milliseconds(30)); }
  // Time passes in steps far shorter than the lease, as while the console
  // waits (a watch starved for 15 steps in a row would see a stop).
  void pass(double seconds) {
    for (double t = 0; t < seconds; t += 0.2) {
      now = now.load() + 0.2;
      settle();
    }
  }
};

TEST(RejoiningCommander, KeepsItsParticipantWhileTheProcessRuns) {
  Rig r;
  r.pass(10);  // ten seconds at the prompt, the watch turning throughout
  EXPECT_EQ(r.gs.hold().message, "participant 1");
  EXPECT_EQ(r.gs.rejoins(), 0);
  EXPECT_EQ(r.log.str(), "");
}

TEST(RejoiningCommander, JoinsAgainAfterAStopLongerThanTheLeaseAndSaysWhy) {
  Rig r;
  r.settle();
  r.now = r.now.load() + 9.7;  // stopped: the watch's next turn sees the gap
  r.settle();
  EXPECT_EQ(r.gs.set_distance(2.5).message, "participant 2");
  EXPECT_EQ(r.gs.rejoins(), 1);
  EXPECT_NE(r.log.str().find("stopped or starved for 9.7 s, longer than its DDS lease (3.0 s"),
            std::string::npos)
      << r.log.str();
  // Once: the next command keeps the new participant.
  EXPECT_EQ(r.gs.hold().message, "participant 2");
  EXPECT_EQ(r.gs.rejoins(), 1);
}

TEST(RejoiningCommander, AJoinThatFailsIsTriedAgainAtTheNextCommand) {
  Rig r;
  r.settle();
  r.now = r.now.load() + 5.0;
  r.settle();
  r.fail_next_join = true;
  EXPECT_THROW(r.gs.land(), std::runtime_error);  // the menu reports it and carries on
  EXPECT_EQ(r.gs.land().message, "participant 2");
  EXPECT_EQ(r.gs.rejoins(), 1);
}

}  // namespace
}  // namespace ddswarm::gs
