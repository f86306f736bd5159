#include "common/process.hpp"

#include <pthread.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <exception>
#include <mutex>
#include <random>
#include <thread>
#include <utility>
#include <vector>

#include "common/config_error.hpp"

namespace ddswarm {
namespace {
std::atomic<bool> g_stop{false};
std::mutex g_mu;
std::condition_variable g_cv;

std::atomic<bool> g_rejoin{false};

struct Wakers {
  std::mutex mu;
  std::uint64_t next = 0;
  std::vector<std::pair<std::uint64_t, std::function<void()>>> wakes;
};
Wakers& wakers() {
  static Wakers w;
  return w;
}

extern "C" void on_signal(int) { g_stop.store(true); }
extern "C" void on_rejoin_signal(int) { g_rejoin.store(true); }

sigset_t signals_of(std::initializer_list<int> sigs) {
  sigset_t set;
  sigemptyset(&set);
  for (int s : sigs) sigaddset(&set, s);
  return set;
}

// Takes the signals that every other thread blocks. Fast DDS's threads wait
// on interprocess semaphores, and boost::interprocess throws on EINTR: a
// SIGTERM handled on one of them ends the process in std::terminate. An
// agent sent SIGTERM while stopped (SIGSTOP) and then SIGCONT is exposed to
// it: a stopped process's signal goes to whichever thread runs first.
void take_signals() {
  const sigset_t set = signals_of({SIGINT, SIGTERM, SIGUSR1});
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
  for (;;) {
    int sig = 0;
    if (sigwait(&set, &sig) != 0) continue;
    if (sig == SIGUSR1) {
      g_rejoin.store(true);
    } else {
      request_stop();
    }
  }
}
}  // namespace

void install_rejoin_signal() {
  struct sigaction sa {};
  sa.sa_handler = on_rejoin_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGUSR1, &sa, nullptr);
  const sigset_t set = signals_of({SIGUSR1});
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
}

void unblock_signals_for_exec() {
  sigset_t none;
  sigemptyset(&none);
  pthread_sigmask(SIG_SETMASK, &none, nullptr);
}

bool take_rejoin_request() { return g_rejoin.exchange(false); }

double rejoin_patience_s(double base_s, int attempt) {
  return base_s * static_cast<double>(1 << std::clamp(attempt, 0, 3));
}

void keep_joining(double duration_s, const std::function<bool(double left_s)>& join) {
  const double end = duration_s > 0 ? wall_seconds() + duration_s : 0;
  while (!stop_requested()) {
    const double left = end > 0 ? end - wall_seconds() : 0;
    if (end > 0 && left <= 0) return;
    if (!join(left)) return;
  }
}

std::string LeaseWatch::turn(double now_s) {
  const double gap = now_s - last_s_;
  last_s_ = now_s;
  if (!(gap > lease_s_)) return "";
  char line[256];
  std::snprintf(
      line, sizeof line,
      "this process was stopped or starved for %.1f s, longer than its DDS lease (%.1f s, "
      "dds.lease_duration_s); leaving DDS and joining again as a new participant",
      gap, lease_s_);
  return line;
}

void settle_after_stop() { wait_for_stop(std::chrono::duration<double>(kSettleAfterStopS)); }

void install_stop_signals() {
  static std::once_flag once;
  std::call_once(once, [] {
    // The handlers serve a thread started before this call, if any.
    struct sigaction sa {};
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);
    std::signal(SIGPIPE, SIG_IGN);
    // Every thread started from here on inherits the mask: only take_signals gets them.
    const sigset_t set = signals_of({SIGINT, SIGTERM});
    pthread_sigmask(SIG_BLOCK, &set, nullptr);
    std::thread(take_signals).detach();
  });
}

bool stop_requested() { return g_stop.load(); }

void request_stop() {
  g_stop.store(true);
  g_cv.notify_all();
  auto& w = wakers();
  std::lock_guard<std::mutex> lock(w.mu);
  for (const auto& [id, wake] : w.wakes) wake();
}

StopWaker::StopWaker(std::function<void()> wake) {
  auto& w = wakers();
  std::lock_guard<std::mutex> lock(w.mu);
  id_ = w.next++;
  w.wakes.emplace_back(id_, std::move(wake));
}

StopWaker::~StopWaker() {
  auto& w = wakers();
  std::lock_guard<std::mutex> lock(w.mu);
  std::erase_if(w.wakes, [this](const auto& e) { return e.first == id_; });
}

bool wait_for_stop(std::chrono::duration<double> d) {
  // A signal handler cannot notify a condition variable (take_signals does);
  // poll in short slices.
  auto end = std::chrono::steady_clock::now() +
             std::chrono::duration_cast<std::chrono::steady_clock::duration>(d);
  std::unique_lock<std::mutex> lock(g_mu);
  while (!g_stop.load()) {
    auto now = std::chrono::steady_clock::now();
    if (now >= end) break;
    std::chrono::steady_clock::duration slice = std::chrono::milliseconds(50);
    g_cv.wait_for(lock, std::min(slice, end - now));
  }
  return g_stop.load();
}

namespace {
struct DeadLockRestart {
  std::string prog;
  std::vector<std::string> args;
  int max_restarts = 0;
  std::terminate_handler previous = nullptr;
  std::atomic<bool> entered{false};
};
DeadLockRestart& dead_lock_restart() {
  static DeadLockRestart r;
  return r;
}

std::int64_t monotonic_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);  // system-wide: it runs on across exec
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

void start_again(DeadLockRestart& r, const std::string& why);

// Execs this program again if the exception in flight is the dead owner's
// lock timeout and the count allows; returns only when it did not.
void try_dead_lock_restart(DeadLockRestart& r) {
  const std::exception_ptr e = std::current_exception();
  if (!e) return;
  std::string what;
  try {
    std::rethrow_exception(e);
  } catch (const std::exception& x) {
    what = x.what();
  } catch (...) {
    return;
  }
  if (!is_dead_owner_lock_timeout(what.c_str())) return;
  start_again(r,
              "a Fast DDS thread met a shared-memory lock whose owner died, a peer killed "
              "while holding it (" +
                  what + ")");
}

// Execs this program again, saying why in one line, unless max_restarts in a
// row were made already; returns only when it did not.
void start_again(DeadLockRestart& r, const std::string& why) {
  const std::int64_t now = monotonic_ns();
  const int n = next_dead_lock_restart(std::getenv(kDeadLockRestartsEnv), now);
  if (n > r.max_restarts) {
    spdlog::error("{}: {}; {} restarts in a row already, so not again", r.prog, why,
                  r.max_restarts);
    spdlog::default_logger()->flush();
    return;
  }
  spdlog::error(
      "{}: {}; starting this process again as a new participant, the same pid ({} of {} in a "
      "row)",
      r.prog, why, n, r.max_restarts);
  spdlog::default_logger()->flush();
  std::fflush(nullptr);
  const std::string count = std::to_string(n) + ":" + std::to_string(now);
  setenv(kDeadLockRestartsEnv, count.c_str(), 1);
  std::vector<char*> argv;
  for (auto& a : r.args) argv.push_back(a.data());
  argv.push_back(nullptr);
  // Nothing of this process's but its standard streams goes on: the new
  // participant makes its own ports, and the old ones' locks go with their
  // descriptors, so the next clean-up sees them as left behind.
  if (close_range(3, ~0U, 0) != 0)
    for (long fd = 3, max = sysconf(_SC_OPEN_MAX); fd < max; ++fd) close(static_cast<int>(fd));
  unblock_signals_for_exec();
  execv("/proc/self/exe", argv.data());
  std::fprintf(stderr, "%s: could not start again: %s\n", r.prog.c_str(), std::strerror(errno));
}

thread_local bool t_in_terminate = false;

void on_terminate() {
  auto& r = dead_lock_restart();
  if (t_in_terminate) std::abort();  // this handler itself failed
  t_in_terminate = true;
  // Two Fast DDS threads may meet the dead lock at once: the first one here
  // ends or restarts the process, and the others must not abort it meanwhile.
  // Bounded, so that nothing hangs if the first one does.
  if (r.entered.exchange(true)) {
    std::this_thread::sleep_for(std::chrono::seconds(10));
    std::abort();
  }
  try_dead_lock_restart(r);
  (r.previous ? r.previous : std::abort)();
}
}  // namespace

bool is_dead_owner_lock_timeout(const char* what) {
  return what != nullptr && std::strstr(what, "owner died without unlocking") != nullptr;
}

int next_dead_lock_restart(const char* env_value, std::int64_t now_ns) {
  int count = 0;
  long long last_ns = 0;
  if (env_value == nullptr || std::sscanf(env_value, "%d:%lld", &count, &last_ns) != 2 || count < 0)
    return 1;
  const double since_s = static_cast<double>(now_ns - last_ns) * 1e-9;
  if (since_s < 0 || since_s > kDeadLockRestartWindowS) return 1;
  return count + 1;
}

int restarts_in_a_row() {
  int count = 0;
  const char* v = std::getenv(kDeadLockRestartsEnv);
  if (v == nullptr || std::sscanf(v, "%d:", &count) != 1 || count < 0) return 0;
  return count;
}

void restart_on_dead_owner_lock(const char* prog, int argc, char** argv, int max_restarts) {
  auto& r = dead_lock_restart();
  r.prog = prog;
  r.args.assign(argv, argv + argc);
  r.max_restarts = max_restarts;
  r.previous = std::set_terminate(on_terminate);
}

struct StuckGuard::State {
  std::mutex mu;
  std::condition_variable cv;
  bool done = false;
};

StuckGuard::StuckGuard(std::string step, double timeout_s) {
  if (dead_lock_restart().args.empty()) return;  // restart_on_dead_owner_lock not called
  state_ = std::make_shared<State>();
  // Detached: a step that ends lets it go at once, and a stuck one is never
  // joined (the exec ends every thread).
  std::thread([st = state_, step = std::move(step), timeout_s] {
    std::unique_lock<std::mutex> lock(st->mu);
    if (st->cv.wait_for(lock, std::chrono::duration<double>(timeout_s), [&] { return st->done; }))
      return;
    auto& r = dead_lock_restart();
    if (r.entered.exchange(true)) return;  // a dead lock's restart is under way
    start_again(r, fmt::format("{} has not ended in {:g} s: a thread of Fast DDS's is stuck (a "
                               "deadlock of Fast DDS 2.9's, docs/faults.md)",
                               step, timeout_s));
    std::fflush(nullptr);
    std::_Exit(1);  // not again, or the exec failed: end rather than hang
  }).detach();
}

StuckGuard::~StuckGuard() {
  if (!state_) return;
  {
    const std::lock_guard<std::mutex> lock(state_->mu);
    state_->done = true;
  }
  state_->cv.notify_all();
}

int run_main(const char* prog, const std::function<int()>& body) {
  try {
    return body();
  } catch (const ConfigError& e) {
    std::fprintf(stderr, "%s: error: %s\n", prog, e.what());
    return 2;
  } catch (const FieldError& e) {
    std::fprintf(stderr, "%s: error: %s\n", prog, e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: error: %s\n", prog, e.what());
    return 1;
  }
}

double wall_seconds() {
  using namespace std::chrono;
  static const auto t0 = steady_clock::now();
  return duration<double>(steady_clock::now() - t0).count();
}

std::uint64_t random_instance() {
  std::random_device rd;
  std::uint64_t v =
      (static_cast<std::uint64_t>(rd()) << 32 | rd()) ^ static_cast<std::uint64_t>(getpid());
  return v ? v : 1;
}

}  // namespace ddswarm
