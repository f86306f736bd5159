#pragma once
// Process lifecycle shared by every executable: stop on SIGINT/SIGTERM,
// turn exceptions into one line and an exit code.
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

namespace ddswarm {

/// SIGINT/SIGTERM request a stop (idempotent). Call it first in main, before
/// any thread starts: it blocks them in the calling thread, so in every thread
/// started afterwards (Fast DDS's), and one thread of its own takes them.
void install_stop_signals();
/// True once a stop was requested (signal or request_stop()).
bool stop_requested();
void request_stop();
/// Sleeps until a stop is requested or d elapses; returns stop_requested().
bool wait_for_stop(std::chrono::duration<double> d);

/// While it lives, runs wake() when a stop is requested (a signal, taken by
/// install_stop_signals' thread, or request_stop()), so a loop that sleeps on
/// a condition variable of its own wakes at once instead of polling
/// stop_requested() in short slices. A process per drone that polled 20
/// times a second spent a tenth of its CPU on it (docs/performance.md).
/// wake runs on the requesting thread while a lock is held that making or
/// destroying a StopWaker also takes: it must not wait for a thread doing
/// either. A stop requested before it was made does not call it: loops test
/// stop_requested() before they sleep.
class StopWaker {
 public:
  explicit StopWaker(std::function<void()> wake);
  ~StopWaker();
  StopWaker(const StopWaker&) = delete;
  StopWaker& operator=(const StopWaker&) = delete;

 private:
  std::uint64_t id_;
};

/// SIGUSR1 asks the process to leave DDS and join again as a new participant
/// (ddswarm-launch sends it to an agent whose endpoints its discovery server
/// dropped). Installs the handler and blocks SIGUSR1 like install_stop_signals
/// (idempotent; call it before any thread starts).
void install_rejoin_signal();
/// In a forked child, before exec: the signals install_stop_signals blocked
/// reach the new program again.
void unblock_signals_for_exec();
/// True once per SIGUSR1 received since the last call.
bool take_rejoin_request();

/// One DDS participant's life after another: join(left_s) runs one, given the
/// wall seconds left of duration_s (0 when duration_s <= 0: no limit), and
/// returns true to leave and join again as a new participant. Ends when it
/// returns false, a stop is requested or duration_s (> 0) has passed.
void keep_joining(double duration_s, const std::function<bool(double left_s)>& join);

/// How long a participant that heard nothing waits before joining again, at
/// its attempt-th try (0 first): base_s, doubled at each try, at most 8 times
/// base_s. Discovery that is slow because a swarm is coming up must not be
/// restarted at a fixed pace: every new participant is more discovery work,
/// and at 128 processes fixed re-joins keep the swarm from ever coming up.
double rejoin_patience_s(double base_s, int attempt);

/// Through a discovery server: seconds without hearing the server after which
/// a tool (ddswarm-gs, bench/swarm_probe) joins again as a new participant,
/// the base of rejoin_patience_s (a healthy one hears it within 1-2 s; at a
/// 128-process bring-up, within 6 s, or 19-27 s on a slower machine).
constexpr double kToolRejoinAfterS = 20.0;

/// Notices that this process was stopped (SIGSTOP, Ctrl-Z, a debugger) or
/// starved for longer than the DDS lease it announces. Its peers may then
/// have dropped it while it still holds them, and Fast DDS 2.9 does not
/// always match the two sides again (docs/faults.md): a new participant is
/// discovered afresh by everyone. A loop that turns often (the agent's, the
/// recorder's) calls turn() at every turn.
///
/// A process that turn() says was stopped waits kSettleAfterStopS
/// (settle_after_stop) before it leaves DDS. On waking, every lease check it
/// holds for its peers is overdue and fires at once; a participant torn down,
/// or a peer's goodbye handled, while those checks run aborts the process on
/// Fast DDS 2.9's assertion in check_remote_participant_liveliness
/// (docs/dds.md): a recorder and a trace stopped and continued together
/// aborted so in 1 run of 20 of mp_fault_recorder_freeze.
class LeaseWatch {
 public:
  LeaseWatch(double lease_s, double now_s) : lease_s_(lease_s), last_s_(now_s) {}
  /// Starts a gap here: the time since the last turn was this process's own
  /// work, not a stop.
  void restart(double now_s) { last_s_ = now_s; }
  /// Ends a gap and starts the next. Returns "" or, when the gap was longer
  /// than the lease, the one-line reason to join again: "this process was
  /// stopped or starved for 9.7 s, longer than its DDS lease (3.0 s,
  /// dds.lease_duration_s); leaving DDS and joining again as a new participant".
  std::string turn(double now_s);

 private:
  double lease_s_, last_s_;
};

/// How long a process that outlived its lease waits before it leaves DDS
/// (LeaseWatch): its overdue lease checks run meanwhile.
inline constexpr double kSettleAfterStopS = 1.0;
/// Waits kSettleAfterStopS, or until a stop is requested.
void settle_after_stop();

/// Fast DDS 2.9 waits 1 s for an interprocess lock, then throws boost's
/// "Interprocess mutex timeout when locking. Possible deadlock: owner died
/// without unlocking?" when a process SIGKILLed while it held a lock in
/// shared memory leaves it held. Thrown on one of Fast DDS's own threads,
/// nothing catches it and the process ends in std::terminate (an agent whose
/// server is killed while it notifies the agent, docs/faults.md). After this
/// call such an end execs this program again instead: the same arguments,
/// environment and PID, no file descriptor but 0-2, and a fresh DDS
/// participant. At most max_restarts in a row (restarts more than
/// kDeadLockRestartWindowS apart are not in a row); any other uncaught
/// exception ends the process as it would without this call. For a process
/// whose state its peers give back (an agent catches up with its mission from
/// the server's samples), not for the server, whose world would start again.
/// Call it in main, after install_stop_signals.
void restart_on_dead_owner_lock(const char* prog, int argc, char** argv, int max_restarts = 3);
/// How many times in a row restart_on_dead_owner_lock (or a StuckGuard) had
/// started this process again when it began (0: its first start).
int restarts_in_a_row();

/// A DDS step (a participant with its endpoints, a reader made anew) that
/// takes longer than this is stuck: such steps take well under a second, and
/// a few seconds for 128 processes starting at once on 2 cores.
constexpr double kDdsStepStuckS = 20.0;

/// Starts this process again, as restart_on_dead_owner_lock does and counted
/// with its restarts, when the step it guards has not ended within
/// timeout_s: Fast DDS 2.9 can deadlock a thread that creates a reader
/// (EDP pairing, which waits for the event thread) against that event
/// thread's participant-lease check (which waits for the PDP lock the first
/// holds), and neither ever returns (docs/faults.md). Past max_restarts in a
/// row the process ends with exit code 1 rather than hang. Inert unless
/// restart_on_dead_owner_lock was called. Destroy it when the step ended.
class StuckGuard {
 public:
  StuckGuard(std::string step, double timeout_s);
  ~StuckGuard();
  StuckGuard(const StuckGuard&) = delete;
  StuckGuard& operator=(const StuckGuard&) = delete;

 private:
  struct State;
  std::shared_ptr<State> state_;
};

/// Whether an exception's what() is Fast DDS's lock timeout on a dead owner.
bool is_dead_owner_lock_timeout(const char* what);
/// Restarts further apart than this (s) start the count again.
constexpr double kDeadLockRestartWindowS = 60.0;
/// The environment variable that carries the count across exec:
/// "<restarts in a row>:<CLOCK_MONOTONIC ns of the last>".
constexpr const char* kDeadLockRestartsEnv = "DDSWARM_DEAD_LOCK_RESTARTS";
/// The pure rule: given the variable's value (nullptr when unset) and the
/// monotonic clock now, the number this restart would be (1 = the first in a row).
int next_dead_lock_restart(const char* env_value, std::int64_t now_ns);

/// Runs body; maps ConfigError/CLI errors to exit 2, other exceptions to exit 1,
/// printing "<prog>: error: <what>" on one line.
int run_main(const char* prog, const std::function<int()>& body);

/// Wall-clock seconds since an arbitrary fixed start (monotonic).
double wall_seconds();

/// A random non-zero 64-bit id for this process instance (agents, servers and
/// ground stations tell a restarted peer from the one they knew by it).
std::uint64_t random_instance();

}  // namespace ddswarm
