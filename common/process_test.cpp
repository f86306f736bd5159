#include "common/process.hpp"

#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <mutex>
#include <optional>
#include <thread>

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
  { const StopWaker gone([&] { ++gone_calls; }); }
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

}  // namespace
}  // namespace ddswarm
