#include "common/process.hpp"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <optional>
#include <regex>
#include <string>
#include <thread>
#include <vector>

namespace ddswarm {
namespace {

TEST(LeaseWatch, AGapLongerThanTheLeaseSaysWhyToJoinAgain) {
  LeaseWatch w(3.0, 100.0);
  EXPECT_EQ(w.turn(100.25), "");
  EXPECT_EQ(w.turn(103.25), "");  // exactly the lease: peers have not dropped it yet
  EXPECT_EQ(w.turn(112.95),
            "this process was stopped or starved for 9.7 s, longer than its DDS lease (3.0 s, "
            "dds.lease_duration_s); leaving DDS and joining again as a new participant");
  EXPECT_EQ(w.turn(113.0), "");  // each gap is measured from the turn before
}

TEST(LeaseWatch, RestartLeavesOwnWorkOutOfTheGap) {
  LeaseWatch w(3.0, 0.0);
  w.restart(10.0);  // e.g. after joining again, which takes its own time
  EXPECT_EQ(w.turn(10.5), "");
}

TEST(RejoinPatience, DoublesAtEachTryUpToEightTimes) {
  EXPECT_EQ(rejoin_patience_s(20.0, 0), 20.0);
  EXPECT_EQ(rejoin_patience_s(20.0, 1), 40.0);
  EXPECT_EQ(rejoin_patience_s(20.0, 2), 80.0);
  EXPECT_EQ(rejoin_patience_s(20.0, 3), 160.0);
  EXPECT_EQ(rejoin_patience_s(20.0, 30), 160.0);  // no overflow, no endless growth
  EXPECT_EQ(rejoin_patience_s(10.0, -1), 10.0);
}

// A loop asleep on its own condition, for up to 30 s, as the agent's main
// loop sleeps between its checks. Returns the seconds it slept.
double sleep_until_stopped(std::mutex& mu, std::condition_variable& cv) {
  const auto t0 = std::chrono::steady_clock::now();
  std::unique_lock<std::mutex> lock(mu);
  cv.wait_for(lock, std::chrono::seconds(30), [] { return stop_requested(); });
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// A SIGTERM, taken by install_stop_signals' thread, wakes the sleeper at
// once; exits 0 when it slept less than the 30 s it would without the waker.
[[noreturn]] void signal_wakes_sleeper() {
  install_stop_signals();
  std::mutex mu;
  std::condition_variable cv;
  const StopWaker waker([&] {
    { const std::lock_guard<std::mutex> lock(mu); }
    cv.notify_all();
  });
  std::thread killer([] {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    kill(getpid(), SIGTERM);
  });
  const double slept = sleep_until_stopped(mu, cv);
  killer.join();
  std::exit(stop_requested() && slept < 20 ? 0 : 1);
}

// A waker destroyed before the stop is not called; a living one is, once.
[[noreturn]] void only_living_wakers_called() {
  int gone_calls = 0;
  int living_calls = 0;
  {
    const StopWaker gone([&] { ++gone_calls; });
  }
  std::optional<StopWaker> living;
  living.emplace([&] { ++living_calls; });
  request_stop();
  living.reset();
  request_stop();  // idempotent, and nobody is left to wake
  std::exit(gone_calls == 0 && living_calls == 1 ? 0 : 1);
}

// A stop is sticky for the whole process, so each case runs in a child.
TEST(StopWaker, ASignalWakesALoopAsleepOnItsOwnCondition) {
  EXPECT_EXIT(signal_wakes_sleeper(), ::testing::ExitedWithCode(0), "");
}

TEST(StopWaker, OnlyTheLivingAreWoken) {
  EXPECT_EXIT(only_living_wakers_called(), ::testing::ExitedWithCode(0), "");
}

// dead_lock_probe (dead_lock_probe.cpp) run to its end: what it printed, and
// its wait status.
struct ProbeRun {
  std::string out;
  int status = 0;
};
ProbeRun run_probe(const std::string& mode, int max_restarts) {
  const std::string cmd = std::string("exec ") + DDSWARM_DEAD_LOCK_PROBE + " " + mode + " " +
                          std::to_string(max_restarts) + " 2>&1";
  ProbeRun r;
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) return r;
  char buf[512];
  while (std::fgets(buf, sizeof buf, p) != nullptr) r.out += buf;
  r.status = pclose(p);
  return r;
}

// The pids and open descriptors of each "run N pid P fds F" line, by N.
struct Runs {
  std::vector<int> pids, fds;
};
Runs runs_of(const std::string& out) {
  Runs r;
  const std::regex line(R"(run (\d+) pid (\d+) fds (\d+))");
  for (std::sregex_iterator it(out.begin(), out.end(), line), end; it != end; ++it) {
    if (std::stoi((*it)[1]) != static_cast<int>(r.pids.size())) break;
    r.pids.push_back(std::stoi((*it)[2]));
    r.fds.push_back(std::stoi((*it)[3]));
  }
  return r;
}

TEST(DeadLockRestart, AFastDdsThreadThatMeetsADeadOwnersLockStartsTheProcessAgain) {
  const ProbeRun r = run_probe("lock-once", 3);
  ASSERT_TRUE(WIFEXITED(r.status) && WEXITSTATUS(r.status) == 0) << r.out;
  const Runs runs = runs_of(r.out);
  ASSERT_EQ(runs.pids.size(), 2u) << r.out;
  EXPECT_EQ(runs.pids[0], runs.pids[1]) << "the same process, the same pid: " << r.out;
  EXPECT_EQ(runs.fds[1], 0) << "no descriptor but 0-2 goes on: " << r.out;
  EXPECT_NE(r.out.find("owner died"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("1 of 3 in a row"), std::string::npos) << r.out;
}

TEST(DeadLockRestart, StopsStartingAgainAfterItsRestartsInARow) {
  const ProbeRun r = run_probe("lock-always", 2);
  EXPECT_TRUE(WIFSIGNALED(r.status) && WTERMSIG(r.status) == SIGABRT) << r.out;
  EXPECT_EQ(runs_of(r.out).pids.size(), 3u) << "the first run and 2 restarts: " << r.out;
  EXPECT_NE(r.out.find("so not again"), std::string::npos) << r.out;
}

// mp_fault_server_lock_kill under load: the agent started again, and its
// main thread deadlocked in Fast DDS creating a reader (against the lease
// timer's thread) and logged nothing for a minute. A step that does not end
// starts the process again, counted with the dead-lock restarts.
TEST(StuckGuard, AStepThatNeverEndsStartsTheProcessAgain) {
  const ProbeRun r = run_probe("stuck-once", 3);
  ASSERT_TRUE(WIFEXITED(r.status) && WEXITSTATUS(r.status) == 0) << r.out;
  const Runs runs = runs_of(r.out);
  ASSERT_EQ(runs.pids.size(), 2u) << r.out;
  EXPECT_EQ(runs.pids[0], runs.pids[1]) << r.out;
  EXPECT_NE(r.out.find("joining DDS has not ended in 0.3 s"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("1 of 3 in a row"), std::string::npos) << r.out;
}

// Past its restarts in a row it ends (exit 1) rather than hang.
TEST(StuckGuard, EndsTheProcessAfterItsRestartsInARow) {
  const ProbeRun r = run_probe("stuck-always", 1);
  EXPECT_TRUE(WIFEXITED(r.status) && WEXITSTATUS(r.status) == 1) << r.out;
  EXPECT_EQ(runs_of(r.out).pids.size(), 2u) << r.out;
  EXPECT_NE(r.out.find("so not again"), std::string::npos) << r.out;
}

TEST(DeadLockRestart, AnyOtherUncaughtExceptionEndsTheProcessAsBefore) {
  const ProbeRun r = run_probe("other", 3);
  EXPECT_TRUE(WIFSIGNALED(r.status) && WTERMSIG(r.status) == SIGABRT) << r.out;
  EXPECT_EQ(runs_of(r.out).pids.size(), 1u) << r.out;
  EXPECT_NE(r.out.find("an unrelated failure"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("starting this process again"), std::string::npos) << r.out;
}

TEST(DeadLockRestart, CountsRestartsInARowWithinItsWindow) {
  const std::int64_t s = 1000000000;
  EXPECT_EQ(next_dead_lock_restart(nullptr, 100 * s), 1);
  EXPECT_EQ(next_dead_lock_restart("1:100000000000", 130 * s), 2);
  EXPECT_EQ(next_dead_lock_restart("2:100000000000", 159 * s), 3);
  EXPECT_EQ(next_dead_lock_restart("2:100000000000", 161 * s), 1) << "long ago: not in a row";
  EXPECT_EQ(next_dead_lock_restart("garbage", 100 * s), 1);
  EXPECT_EQ(next_dead_lock_restart("1:200000000000", 100 * s), 1) << "from the future";
  EXPECT_TRUE(is_dead_owner_lock_timeout(
      "Interprocess mutex timeout when locking. Possible deadlock: owner died without unlocking?"));
  EXPECT_FALSE(is_dead_owner_lock_timeout("Interprocess mutex timeout when locking"));
  EXPECT_FALSE(is_dead_owner_lock_timeout(nullptr));
}

}  // namespace
}  // namespace ddswarm
