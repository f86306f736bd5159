// A test program for restart_on_dead_owner_lock (process_test.cpp): prints
// "run <restarts> pid <pid> fds <descriptors above 2>", then, unless it has
// been started again and argv[1] is "lock-once", throws on a thread of its
// own as Fast DDS's threads do: the dead owner's lock timeout for "lock-once"
// and "lock-always", anything else for "other". "stuck-once" and
// "stuck-always" instead never end a step a StuckGuard of 0.3 s guards.
// argv[2]: max restarts.
#include <dirent.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <thread>

#include "common/process.hpp"

namespace {
int open_fds_above_2() {
  int n = 0;
  if (DIR* d = opendir("/proc/self/fd")) {
    const int own = dirfd(d);
    while (const dirent* e = readdir(d))
      if (e->d_name[0] != '.' && std::atoi(e->d_name) > 2 && std::atoi(e->d_name) != own) ++n;
    closedir(d);
  }
  return n;
}
}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) return 2;
  const std::string mode = argv[1];
  ddswarm::install_stop_signals();
  ddswarm::restart_on_dead_owner_lock("dead_lock_probe", argc, argv, std::atoi(argv[2]));
  const int runs = ddswarm::restarts_in_a_row();
  std::printf("run %d pid %d fds %d\n", runs, static_cast<int>(getpid()), open_fds_above_2());
  std::fflush(stdout);
  if ((mode == "lock-once" || mode == "stuck-once") && runs >= 1) return 0;
  if (mode.rfind("stuck", 0) == 0) {
    const ddswarm::StuckGuard guard("joining DDS", 0.3);
    for (;;) std::this_thread::sleep_for(std::chrono::seconds(1));  // as a deadlocked thread
  }
  std::thread([&] {
    throw std::runtime_error(mode == "other" ? "an unrelated failure"
                                             : "Interprocess mutex timeout when locking. Possible "
                                               "deadlock: owner died without unlocking?");
  }).join();
  return 0;
}
