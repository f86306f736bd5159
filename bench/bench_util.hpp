#pragma once
// Small helpers the scale benches share: start and stop child processes by
// PID, read a process's CPU time and memory from /proc.
#include <sys/types.h>

#include <map>
#include <string>
#include <vector>

namespace ddswarm::bench {

/// Forks and execs argv; the child dies with us (PR_SET_PDEATHSIG) and writes
/// stdout/stderr to log_file (/dev/null when empty). Throws naming argv[0].
pid_t spawn(const std::vector<std::string>& argv, const std::string& log_file = "");
/// SIGTERM to each, SIGKILL to those alive after grace_s; reaps all. Clears pids.
void stop_all(std::vector<pid_t>& pids, double grace_s = 3.0);
/// A UDP port on 127.0.0.1 that was free a moment ago.
int free_udp_port();
/// Starts fast-discovery-server on 127.0.0.1:port with config/discovery_server.xml.
pid_t start_discovery_server(int port, const std::string& log_file = "");

struct ProcSample {
  std::string comm;  ///< executable name (15 characters at most)
  double cpu_s = 0;  ///< user + system CPU seconds so far
  long rss_kb = 0;   ///< resident set
  long pss_kb = 0;   ///< proportional set (shared pages split), 0 when unreadable
  int threads = 0;
};
/// Reads /proc/<pid>; false when the process is gone.
bool sample(pid_t pid, ProcSample& out, bool with_pss = false);
/// Every descendant of root (children, grandchildren, ...), not root itself.
std::vector<pid_t> descendants(pid_t root);
/// CPU seconds per pid for the given pids (missing ones are left out).
std::map<pid_t, ProcSample> sample_all(const std::vector<pid_t>& pids, bool with_pss = false);

/// Path of the running executable.
std::string self_exe();

}  // namespace ddswarm::bench
