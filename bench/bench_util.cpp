#include "bench/bench_util.hpp"

#include <arpa/inet.h>
#include <dirent.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace ddswarm::bench {

namespace {
/// argv0 itself when it names a path, else the first match on $PATH ("" when none).
std::string resolve(const std::string& argv0) {
  if (argv0.find('/') != std::string::npos) return access(argv0.c_str(), X_OK) == 0 ? argv0 : "";
  std::stringstream path(getenv("PATH") ? getenv("PATH") : "/usr/bin:/bin");
  std::string dir;
  while (std::getline(path, dir, ':'))
    if (access((dir + "/" + argv0).c_str(), X_OK) == 0) return dir + "/" + argv0;
  return "";
}
}  // namespace

pid_t spawn(const std::vector<std::string>& argv, const std::string& log_file) {
  if (resolve(argv.at(0)).empty())
    throw std::runtime_error("cannot run " + argv[0] + ": not found or not executable");
  const pid_t parent = getpid();
  pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed for " + argv[0]);
  if (pid == 0) {
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(127);
    int fd =
        open(log_file.empty() ? "/dev/null" : log_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      dup2(fd, STDOUT_FILENO);
      dup2(fd, STDERR_FILENO);
      close(fd);
    }
    std::vector<char*> a;
    for (const auto& s : argv) a.push_back(const_cast<char*>(s.c_str()));
    a.push_back(nullptr);
    execvp(a[0], a.data());
    std::fprintf(stderr, "cannot exec %s: %s\n", a[0], std::strerror(errno));
    _exit(127);
  }
  return pid;
}

void stop_all(std::vector<pid_t>& pids, double grace_s) {
  for (pid_t p : pids) kill(p, SIGTERM);
  auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(grace_s);
  std::vector<pid_t> left = pids;
  while (!left.empty() && std::chrono::steady_clock::now() < deadline) {
    std::erase_if(left, [](pid_t p) { return waitpid(p, nullptr, WNOHANG) == p; });
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  for (pid_t p : left) kill(p, SIGKILL);
  for (pid_t p : left) waitpid(p, nullptr, 0);
  pids.clear();
}

int free_udp_port() {
  int s = socket(AF_INET, SOCK_DGRAM, 0);
  if (s < 0) throw std::runtime_error("socket failed");
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = 0;
  socklen_t len = sizeof a;
  if (bind(s, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 ||
      getsockname(s, reinterpret_cast<sockaddr*>(&a), &len) != 0) {
    close(s);
    throw std::runtime_error("cannot find a free UDP port on 127.0.0.1");
  }
  close(s);
  return ntohs(a.sin_port);
}

pid_t start_discovery_server(int port, const std::string& log_file) {
  return spawn({"fast-discovery-server", "-i", "0", "-l", "127.0.0.1", "-p", std::to_string(port),
                "-x", std::string(DDSWARM_CONFIG_DIR) + "/discovery_server.xml"},
               log_file);
}

bool sample(pid_t pid, ProcSample& out, bool with_pss) {
  const std::string dir = "/proc/" + std::to_string(pid);
  std::ifstream f(dir + "/stat");
  std::string text;
  if (!std::getline(f, text)) return false;
  // comm may hold spaces: fields resume after the last ')'.
  auto open = text.find('('), close = text.rfind(')');
  if (open == std::string::npos || close == std::string::npos) return false;
  out.comm = text.substr(open + 1, close - open - 1);
  std::istringstream rest(text.substr(close + 2));
  std::vector<std::string> fld;
  std::string x;
  while (rest >> x) fld.push_back(x);
  // fld[0] is field 3 (state); utime is field 14, stime 15, num_threads 20, rss 24.
  if (fld.size() < 22) return false;
  const double tck = static_cast<double>(sysconf(_SC_CLK_TCK));
  out.cpu_s = (std::stod(fld[11]) + std::stod(fld[12])) / tck;
  out.threads = std::stoi(fld[17]);
  out.rss_kb = std::stol(fld[21]) * (sysconf(_SC_PAGESIZE) / 1024);
  out.pss_kb = 0;
  if (with_pss) {
    std::ifstream sm(dir + "/smaps_rollup");
    std::string line;
    while (std::getline(sm, line))
      if (line.rfind("Pss:", 0) == 0) out.pss_kb = std::stol(line.substr(4));
  }
  return true;
}

std::vector<pid_t> descendants(pid_t root) {
  std::map<pid_t, std::vector<pid_t>> kids;
  if (DIR* d = opendir("/proc")) {
    while (dirent* e = readdir(d)) {
      pid_t p = std::atoi(e->d_name);
      if (p <= 0) continue;
      std::ifstream f("/proc/" + std::to_string(p) + "/stat");
      std::string text;
      if (!std::getline(f, text)) continue;
      auto close = text.rfind(')');
      if (close == std::string::npos) continue;
      std::istringstream rest(text.substr(close + 2));
      std::string state;
      pid_t ppid = 0;
      rest >> state >> ppid;
      kids[ppid].push_back(p);
    }
    closedir(d);
  }
  std::vector<pid_t> out, todo = {root};
  while (!todo.empty()) {
    pid_t p = todo.back();
    todo.pop_back();
    for (pid_t c : kids[p]) {
      out.push_back(c);
      todo.push_back(c);
    }
  }
  return out;
}

std::map<pid_t, ProcSample> sample_all(const std::vector<pid_t>& pids, bool with_pss) {
  std::map<pid_t, ProcSample> out;
  for (pid_t p : pids) {
    ProcSample s;
    if (sample(p, s, with_pss)) out[p] = s;
  }
  return out;
}

std::string self_exe() { return std::filesystem::read_symlink("/proc/self/exe").string(); }

}  // namespace ddswarm::bench
