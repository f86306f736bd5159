// What ddswarm.launch() needs from C++: a child that dies with its parent,
// a free DDS domain found as ddswarm's own tools find one, and the
// scenario with overrides written as ddswarm-launch writes it.
#include "python/process.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include "common/domain_claim.hpp"
#include "common/scenario_overrides.hpp"
#include "common/yaml_section.hpp"

namespace ddswarm::py_api {

int spawn_session(const std::vector<std::string>& argv, const std::string& log_path) {
  if (argv.empty()) throw std::invalid_argument("spawn: no program");
  if (access(argv[0].c_str(), X_OK) != 0)
    throw std::runtime_error("cannot run " + argv[0] + ": " + std::strerror(errno));
  const int log = open(log_path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (log < 0) throw std::runtime_error("cannot write " + log_path + ": " + std::strerror(errno));
  const int devnull = open("/dev/null", O_RDONLY | O_CLOEXEC);
  // Everything the child needs, made before fork: after it, in a process
  // with threads (Fast DDS's, Python's), only async-signal-safe calls.
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) {
    close(log);
    if (devnull >= 0) close(devnull);
    throw std::runtime_error("fork failed for " + argv[0]);
  }
  if (pid == 0) {
    // Its own session: the terminal's Ctrl-C reaches Python only, which
    // stops the swarm in order. SIGTERM when the thread that started it
    // ends, whatever ends it (SIGKILL included).
    setsid();
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(127);  // the parent died before prctl
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    signal(SIGPIPE, SIG_DFL);
    if (devnull >= 0) dup2(devnull, STDIN_FILENO);
    dup2(log, STDOUT_FILENO);
    dup2(log, STDERR_FILENO);
    execv(args[0], args.data());
    _exit(127);
  }
  close(log);
  if (devnull >= 0) close(devnull);
  return pid;
}

std::pair<int, std::vector<std::string>> free_domain(int first) {
  std::vector<std::string> skipped;
  auto claims = claim_free_domains(first, 1, &skipped);
  // Let go at once: ddswarm-launch claims it for the swarm's life (a claim
  // is one open file, which a child does not inherit).
  return {claims.empty() ? -1 : claims.front().domain(), skipped};
}

void derive_scenario(const std::string& path, const std::vector<std::string>& sets,
                     const std::string& out) {
  YAML::Node derived =
      apply_overrides(YamlDocument::load_file(path).root(), parse_set_options(sets, "set"));
  std::ofstream f(out);
  f << "# " << path << " with set= overrides\n" << YAML::Dump(derived) << "\n";
  if (!f) throw std::runtime_error("cannot write " + out);
}

}  // namespace ddswarm::py_api
