#include "launcher/launcher.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <fmt/format.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "common/dds_config.hpp"
#include "common/process.hpp"

namespace ddswarm::gs {

std::string ChildExit::describe() const {
  std::ostringstream os;
  os << name << " (pid " << pid << ")";
  if (signal) {
    const char* s = sigabbrev_np(signal);
    os << " was killed by SIG" << (s ? s : std::to_string(signal).c_str());
  } else {
    os << " exited with code " << exit_code;
  }
  return os.str();
}

Launcher::Launcher(std::string log_dir) : log_dir_(std::move(log_dir)) {
  if (!log_dir_.empty()) std::filesystem::create_directories(log_dir_);
  if (pipe2(wake_, O_CLOEXEC) != 0) throw std::runtime_error("pipe failed");
  pump_ = std::thread([this] { pump(); });
}

Launcher::~Launcher() {
  stop_all();
  quit_ = true;
  char b = 0;
  (void)!write(wake_[1], &b, 1);
  if (pump_.joinable()) pump_.join();
  close(wake_[0]);
  close(wake_[1]);
  for (auto& c : closed_)
    if (c->log) fclose(c->log);
}

std::string Launcher::self_dir() {
  std::error_code ec;
  auto p = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::string(".") : p.parent_path().string();
}

namespace {

/// Forks and execs spec with its stdout and stderr into a new pipe, the child
/// dying with this process (SIGTERM). new_group: the child leads its own
/// process group, so Ctrl-C reaches only the launcher, which stops children in
/// order. Returns the pid and the pipe's read end; throws std::runtime_error
/// naming the program when it cannot start.
std::pair<pid_t, int> spawn_piped(const ChildSpec& spec, bool new_group) {
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error("pipe failed");
  if (access(spec.argv.at(0).c_str(), X_OK) != 0) {
    close(fds[0]);
    close(fds[1]);
    throw std::runtime_error("cannot run " + spec.argv[0] + ": " + std::strerror(errno));
  }
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) {
    close(fds[0]);
    close(fds[1]);
    throw std::runtime_error("fork failed for " + spec.name);
  }
  if (pid == 0) {
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(127);  // the parent died before prctl
    if (new_group) setpgid(0, 0);
    unblock_signals_for_exec();
    dup2(fds[1], STDOUT_FILENO);
    dup2(fds[1], STDERR_FILENO);
    std::vector<char*> argv;
    for (const auto& a : spec.argv) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(argv[0], argv.data());
    std::fprintf(stderr, "cannot exec %s: %s\n", argv[0], std::strerror(errno));
    _exit(127);
  }
  close(fds[1]);
  return {pid, fds[0]};
}

}  // namespace

ChildExit run_to_end(const ChildSpec& spec, std::string& output) {
  const auto [pid, out_fd] = spawn_piped(spec, false);
  output.clear();
  char buf[4096];
  for (;;) {
    const ssize_t n = read(out_fd, buf, sizeof buf);
    if (n > 0) {
      output.append(buf, static_cast<std::size_t>(n));
    } else if (n == 0 || errno != EINTR) {
      break;
    }
  }
  close(out_fd);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  ChildExit e;
  e.name = spec.name;
  e.pid = pid;
  if (WIFEXITED(status)) e.exit_code = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) e.signal = WTERMSIG(status);
  return e;
}

pid_t Launcher::start(const ChildSpec& spec) {
  const auto [pid, out_fd] = spawn_piped(spec, true);
  auto c = std::make_unique<Child>();
  c->name = spec.name;
  c->pid = pid;
  c->out_fd = out_fd;
  c->ready_line = spec.ready_line;
  if (!log_dir_.empty()) {
    std::string file = spec.name;
    for (auto& ch : file)
      if (ch == ' ' || ch == '/') ch = '_';
    bool again = false;  // a restart: keep what the earlier run wrote
    {
      std::lock_guard<std::mutex> lock(mu_);
      again = !logs_opened_.insert(file).second;
    }
    c->log = fopen((log_dir_ + "/" + file + ".log").c_str(), again ? "a" : "w");
  }
  {
    std::lock_guard<std::mutex> lock(mu_);
    live_[pid] = std::move(c);
  }
  char b = 0;
  (void)!write(wake_[1], &b, 1);
  return pid;
}

void Launcher::rejoin_dropped_participants(const std::string& ds_name) {
  std::lock_guard<std::mutex> lock(mu_);
  drop_watch_ = ds_name;
}

bool Launcher::wait_ready(const std::string& name, double timeout_s) {
  const double end = wall_seconds() + timeout_s;
  for (;;) {
    {
      std::lock_guard<std::mutex> lock(mu_);
      const auto it = std::find_if(live_.begin(), live_.end(),
                                   [&](const auto& kv) { return kv.second->name == name; });
      if (it == live_.end()) return false;  // reaped (or never started)
      if (it->second->ready) return true;
      if (it->second->out_fd < 0) return false;  // its output ended: it has exited
    }
    if (wall_seconds() >= end || wait_for_stop(std::chrono::milliseconds(50))) return false;
  }
}

void Launcher::on_dropped(const std::array<std::uint8_t, 12>& prefix, bool server_only) {
  const int pid16 = prefix_pid16(prefix);
  const auto it = std::find_if(live_.begin(), live_.end(),
                               [&](const auto& kv) { return (kv.first & 0xffff) == pid16; });
  const Child* c = it == live_.end() ? nullptr : it->second.get();
  if (server_only && !(c && c->name == "sim")) return;
  if (!dropped_seen_.insert(prefix).second) return;  // one participant: several endpoint lines
  std::string guid;
  for (auto b : prefix) guid += fmt::format("{}{:02x}", guid.empty() ? "" : ".", b);
  if (!c) {  // a tool that joined by itself: it says so when it finds no server
    std::cerr << "ddswarm-launch: the discovery server dropped the endpoints of participant "
              << guid << ", not one of this launch's processes\n";
  } else if (c->name.rfind("agent", 0) == 0 || c->name == "sim") {
    std::cerr << "ddswarm-launch: the discovery server dropped " << c->name
              << "'s endpoints (participant " << guid << "); asking it to join again\n";
    kill(c->pid, SIGUSR1);
  } else {
    std::cerr << "ddswarm-launch: warning: the discovery server dropped " << c->name
              << "'s endpoints (participant " << guid
              << "); Fast DDS 2.9 never matches them afterwards\n";
  }
}

void Launcher::emit(Child& c, const char* data, std::size_t n, bool flush) {
  c.partial.append(data, n);
  std::size_t start = 0, nl;
  while ((nl = c.partial.find('\n', start)) != std::string::npos ||
         (flush && start < c.partial.size())) {
    std::size_t end = nl == std::string::npos ? c.partial.size() : nl;
    std::string line = c.partial.substr(start, end - start);
    if (!c.ready_line.empty() && line.find(c.ready_line) != std::string::npos) c.ready = true;
    if (!drop_watch_.empty() && c.name == drop_watch_) {
      if (auto prefix = dropped_participant_prefix(line)) on_dropped(*prefix, false);
      if (auto prefix = unmatched_participant_prefix(line)) on_dropped(*prefix, true);
    }
    if (c.log) {
      fprintf(c.log, "%s\n", line.c_str());
      fflush(c.log);
    } else {
      std::string out = "[" + c.name + "] " + line + "\n";
      fwrite(out.data(), 1, out.size(), stdout);
      fflush(stdout);
    }
    start = end + 1;
    if (nl == std::string::npos) break;
  }
  c.partial.erase(0, std::min(start, c.partial.size()));
}

void Launcher::pump() {
  std::vector<pollfd> fds;
  std::vector<Child*> owners;
  char buf[8192];
  while (!quit_) {
    fds.clear();
    owners.clear();
    fds.push_back({wake_[0], POLLIN, 0});
    owners.push_back(nullptr);
    {
      std::lock_guard<std::mutex> lock(mu_);
      for (auto& [pid, c] : live_)
        if (c->out_fd >= 0) {
          fds.push_back({c->out_fd, POLLIN, 0});
          owners.push_back(c.get());
        }
    }
    if (poll(fds.data(), fds.size(), 200) <= 0) continue;
    if (fds[0].revents) (void)!read(wake_[0], buf, sizeof buf);
    for (std::size_t i = 1; i < fds.size(); ++i) {
      if (!fds[i].revents) continue;
      // Under the lock, and only while the fd is still this child's: reap()
      // may have drained and closed it since poll(), and a new child's pipe
      // may have the same number by now (a race TSan found).
      std::lock_guard<std::mutex> lock(mu_);
      Child* c = owners[i];
      if (c->out_fd != fds[i].fd) continue;
      ssize_t n = read(c->out_fd, buf, sizeof buf);
      if (n > 0) {
        emit(*c, buf, static_cast<std::size_t>(n), false);
      } else {
        emit(*c, "", 0, true);
        close(c->out_fd);
        c->out_fd = -1;
      }
    }
  }
}

std::vector<ChildExit> Launcher::reap() {
  std::vector<ChildExit> out;
  std::lock_guard<std::mutex> lock(mu_);
  for (auto it = live_.begin(); it != live_.end();) {
    int status = 0;
    pid_t r = waitpid(it->first, &status, WNOHANG);
    if (r == it->first) {
      ChildExit e;
      e.name = it->second->name;
      e.pid = r;
      if (WIFEXITED(status)) e.exit_code = WEXITSTATUS(status);
      if (WIFSIGNALED(status)) e.signal = WTERMSIG(status);
      out.push_back(e);
      // Drain what the child wrote before it died.
      if (it->second->out_fd >= 0) {
        char buf[8192];
        int flags = fcntl(it->second->out_fd, F_GETFL);
        fcntl(it->second->out_fd, F_SETFL, flags | O_NONBLOCK);
        ssize_t n;
        while ((n = read(it->second->out_fd, buf, sizeof buf)) > 0)
          emit(*it->second, buf, n, false);
        emit(*it->second, "", 0, true);
        close(it->second->out_fd);
        it->second->out_fd = -1;
      }
      closed_.push_back(std::move(it->second));
      it = live_.erase(it);
    } else {
      ++it;
    }
  }
  return out;
}

int Launcher::running() const {
  std::lock_guard<std::mutex> lock(mu_);
  return static_cast<int>(live_.size());
}

bool Launcher::signal(const std::string& name, int sig) {
  std::lock_guard<std::mutex> lock(mu_);
  for (const auto& [pid, c] : live_)
    if (c->name == name) return kill(pid, sig) == 0;
  return false;
}

std::vector<ChildExit> Launcher::stop_all(double grace_s) {
  std::vector<ChildExit> out;
  {
    std::lock_guard<std::mutex> lock(mu_);
    for (const auto& [pid, c] : live_) kill(pid, SIGTERM);
  }
  auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(grace_s);
  while (running() > 0 && std::chrono::steady_clock::now() < deadline) {
    for (auto& e : reap()) out.push_back(e);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  {
    std::lock_guard<std::mutex> lock(mu_);
    for (const auto& [pid, c] : live_) kill(pid, SIGKILL);
  }
  while (running() > 0) {
    for (auto& e : reap()) out.push_back(e);
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return out;
}

DiscoveryServerChoice parse_discovery_server(const std::string& text) {
  DiscoveryServerChoice c;
  if (text == "auto") return c;
  if (text == "on") {
    c.kind = DiscoveryServerChoice::Kind::kOn;
    return c;
  }
  if (text == "off") {
    c.kind = DiscoveryServerChoice::Kind::kOff;
    return c;
  }
  auto colon = text.find(':');
  in_addr a{};
  const std::string host = text.substr(0, colon);
  bool port_ok = colon != std::string::npos && colon + 1 < text.size() &&
                 text.find_first_not_of("0123456789", colon + 1) == std::string::npos &&
                 text.size() - colon - 1 <= 5 && std::stoi(text.substr(colon + 1)) > 0 &&
                 std::stoi(text.substr(colon + 1)) < 65536;
  if (inet_pton(AF_INET, host.c_str(), &a) != 1 || !port_ok)
    throw std::invalid_argument("--discovery-server " + text +
                                ": must be auto, on, off or IPv4:port");
  c.kind = DiscoveryServerChoice::Kind::kExternal;
  c.address = text;
  return c;
}

bool wants_local_discovery_server(const DiscoveryServerChoice& c, int drones,
                                  bool starts_whole_swarm, bool localhost_discovery) {
  switch (c.kind) {
    case DiscoveryServerChoice::Kind::kOn:
      return true;
    case DiscoveryServerChoice::Kind::kAuto:
      return drones > kAutoDiscoveryServerAbove && starts_whole_swarm && localhost_discovery;
    default:
      return false;
  }
}

int agent_participant_id(int drones, int drone_id) {
  if (drones <= kExplicitParticipantIdsAbove) return -1;
  const int pid = kFirstAgentParticipantId + drone_id;
  return pid <= kMaxParticipantId ? pid : -1;
}

std::vector<std::string> agent_host_shares(const std::vector<int>& ids, int hosts) {
  std::vector<std::string> shares;
  if (hosts <= 0 || ids.empty()) return shares;
  const std::size_t per = (ids.size() + hosts - 1) / hosts;
  for (std::size_t lo = 0; lo < ids.size(); lo += per) {
    std::string share;
    for (std::size_t k = lo; k < std::min(ids.size(), lo + per); ++k)
      share += (share.empty() ? "" : ",") + std::to_string(ids[k]);
    shares.push_back(share);
  }
  return shares;
}

bool worth_restarting(const ChildExit& e) {
  if (e.signal != 0) return true;
  return e.exit_code != 0 && e.exit_code != 2 && e.exit_code != 3;
}

OnDeath parse_on_death(const std::string& text) {
  if (text == "stop") return OnDeath::kStop;
  if (text == "keep") return OnDeath::kKeep;
  if (text == "restart") return OnDeath::kRestart;
  throw std::invalid_argument("--on-death = " + text + ": must be stop, keep or restart");
}

std::optional<ChildSpec> DeathPolicy::ended(const ChildExit& e) {
  const auto always = always_.find(e.name);
  const auto spec = always != always_.end() ? always : restartable_.find(e.name);
  const bool may =
      always != always_.end() || (policy_ == OnDeath::kRestart && spec != restartable_.end());
  if (may && worth_restarting(e) && restarts_[e.name] < kMaxRestarts) {
    ++restarts_[e.name];
    return spec->second;
  }
  died_ = true;
  return std::nullopt;
}

int DeathPolicy::restarts(const std::string& name) const {
  const auto it = restarts_.find(name);
  return it == restarts_.end() ? 0 : it->second;
}

std::vector<std::string> agent_command(const std::string& bin, const std::string& ids, bool host,
                                       const std::string& scenario, bool started_with_server) {
  std::vector<std::string> a = {bin + "/ddswarm-agent", host ? "--ids" : "--id", ids, "--config",
                                scenario};
  if (started_with_server) a.insert(a.end(), {"--duplicate-probe", "0"});
  return a;
}

std::string ephemeral_port_warning(int domain, int first_id, int last_id, PortRange ephemeral) {
  const auto [lo, hi] = ephemeral;
  const int low = rtps_unicast_port(domain, first_id),
            high = rtps_unicast_port(domain, last_id) + 1;
  if (first_id < 0 || last_id < first_id || high < lo || low > hi) return "";
  const int clear_domain =
      (lo - 1 - rtps_unicast_port(0, last_id) - 1) / 250;  // largest d with every port below lo
  return fmt::format(
      "participant ids {}-{} in domain {} use RTPS ports {}-{}, inside this machine's ephemeral "
      "port range {}-{}: a participant whose port another socket holds is never discovered; "
      "use --domain {} or lower",
      first_id, last_id, domain, low, high, lo, hi, std::max(0, clear_domain));
}

ChildSpec discovery_server_spec(int port) {
  std::string exe;
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "/usr/bin:/bin");
  std::string dir;
  while (exe.empty() && std::getline(dirs, dir, ':'))
    if (access((dir + "/fast-discovery-server").c_str(), X_OK) == 0)
      exe = dir + "/fast-discovery-server";
  if (exe.empty())
    throw std::runtime_error(
        "fast-discovery-server not found (Debian package fastdds-tools; ./scripts/setup installs "
        "it)");
  return {"discovery-server",
          {exe, "-i", "0", "-l", "127.0.0.1", "-p", std::to_string(port), "-x",
           std::string(DDSWARM_CONFIG_DIR) + "/discovery_server.xml"}};
}

namespace {
/// The GUID prefix right before the first '|' of a log line, colour codes aside.
std::optional<std::array<std::uint8_t, 12>> prefix_before_bar(const std::string& line) {
  std::string plain;  // without ANSI colour codes (ESC [ ... letter)
  for (std::size_t i = 0; i < line.size(); ++i) {
    if (line[i] == '\x1b' && i + 1 < line.size() && line[i + 1] == '[') {
      i += 2;
      while (i < line.size() && !std::isalpha(static_cast<unsigned char>(line[i]))) ++i;
      continue;
    }
    plain += line[i];
  }
  // "<12 hex pairs separated by dots>|<entity id>"
  const auto bar = plain.find('|');
  if (bar == std::string::npos || bar < 35) return std::nullopt;
  const std::string guid = plain.substr(bar - 35, 35);
  std::array<std::uint8_t, 12> out{};
  for (int k = 0; k < 12; ++k) {
    const std::string byte = guid.substr(3 * k, 2);
    if (!std::isxdigit(static_cast<unsigned char>(byte[0])) ||
        !std::isxdigit(static_cast<unsigned char>(byte[1])) || (k < 11 && guid[3 * k + 2] != '.'))
      return std::nullopt;
    out[k] = static_cast<std::uint8_t>(std::stoi(byte, nullptr, 16));
  }
  return out;
}
}  // namespace

std::optional<std::array<std::uint8_t, 12>> dropped_participant_prefix(const std::string& line) {
  if (line.find("has no associated participant") == std::string::npos) return std::nullopt;
  return prefix_before_bar(line);
}

std::optional<std::array<std::uint8_t, 12>> unmatched_participant_prefix(const std::string& line) {
  if (line.find("Matching unexisting participant from") == std::string::npos) return std::nullopt;
  return prefix_before_bar(line);
}

int prefix_pid16(const std::array<std::uint8_t, 12>& prefix) {
  return prefix[4] | (prefix[5] << 8);
}

int free_udp_port() {
  int s = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (s < 0) throw std::runtime_error("cannot open a UDP socket to find a free port");
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof a;
  bool ok = bind(s, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0 &&
            getsockname(s, reinterpret_cast<sockaddr*>(&a), &len) == 0;
  close(s);
  if (!ok) throw std::runtime_error("cannot find a free UDP port on 127.0.0.1");
  return ntohs(a.sin_port);
}

}  // namespace ddswarm::gs
