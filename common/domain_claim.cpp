#include "common/domain_claim.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>

#include "common/dds_config.hpp"
#include "common/shm_clean.hpp"

namespace ddswarm {
namespace {

std::string claim_path(const std::string& dir, int domain_id) {
  return dir + "/ddswarm_domain_" + std::to_string(domain_id) + ".lock";
}

/// This process's command line, its arguments joined by spaces.
std::string own_command_line() {
  std::ifstream in("/proc/self/cmdline", std::ios::binary);
  std::string raw((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  while (!raw.empty() && raw.back() == '\0') raw.pop_back();
  for (char& c : raw)
    if (c == '\0') c = ' ';
  return raw;
}

}  // namespace

DomainClaim::DomainClaim(int domain_id, const std::string& dir) : domain_(domain_id) {
  const std::string path = claim_path(dir, domain_id);
  // Any user may claim a domain: the file is made writable by all, and one
  // that another user made without that (an older umask) is locked read-only.
  bool writable = true;
  int fd = open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
  if (fd >= 0) {
    fchmod(fd, 0666);  // not ours to change if another user made it: no matter
  } else {
    writable = false;
    fd = open(path.c_str(), O_RDONLY | O_CLOEXEC);
  }
  if (fd < 0) {
    holder_ = "cannot open " + path + ": " + std::strerror(errno);
    return;
  }
  if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
    std::ifstream in(path);
    std::getline(in, holder_);
    // A holder that could not write its note (another user's file) leaves
    // the last writer's: name no one rather than a process that is gone.
    long pid = 0;
    if (std::sscanf(holder_.c_str(), "pid %ld:", &pid) != 1 || pid <= 0 ||
        (kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH))
      holder_ = "another process (" + path + ")";
    close(fd);
    return;
  }
  fd_ = fd;
  const std::string who = "pid " + std::to_string(getpid()) + ": " + own_command_line() + "\n";
  if (writable && ftruncate(fd_, 0) == 0 && pwrite(fd_, who.data(), who.size(), 0) < 0) {
    // The claim holds without its note; whoever finds it taken reads no name.
  }
}

DomainClaim::~DomainClaim() {
  if (fd_ >= 0) close(fd_);  // closing the only descriptor lets the lock go
}

DomainClaim::DomainClaim(DomainClaim&& other) noexcept
    : domain_(other.domain_), fd_(other.fd_), holder_(std::move(other.holder_)) {
  other.fd_ = -1;
}

DomainClaim& DomainClaim::operator=(DomainClaim&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) close(fd_);
    domain_ = other.domain_;
    fd_ = other.fd_;
    holder_ = std::move(other.holder_);
    other.fd_ = -1;
  }
  return *this;
}

std::vector<DomainClaim> claim_free_domains(int first, int count,
                                            std::vector<std::string>* why_skipped,
                                            const std::string& dir) {
  std::vector<DomainClaim> out;
  for (int domain = first; domain <= kMaxDomainId && static_cast<int>(out.size()) < count;
       ++domain) {
    DomainClaim c(domain, dir);
    std::string why;
    if (!c.held())
      why = c.holder();
    else if (domain_has_live_participants(domain, dir))
      why = "DDS participants on this host use it";
    if (why.empty()) {
      out.push_back(std::move(c));
    } else if (why_skipped) {
      why_skipped->push_back("domain " + std::to_string(domain) + ": " + why);
    }
  }
  return out;
}

}  // namespace ddswarm
