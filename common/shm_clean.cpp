#include "common/shm_clean.hpp"

#include "common/dds_config.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <set>
#include <vector>

namespace ddswarm {
namespace {

bool starts_with(const std::string& s, const std::string& p) { return s.rfind(p, 0) == 0; }
bool ends_with(const std::string& s, const std::string& p) {
  return s.size() >= p.size() && s.compare(s.size() - p.size(), p.size(), p) == 0;
}

std::vector<std::string> list_dir(const std::string& dir) {
  std::vector<std::string> out;
  if (DIR* d = opendir(dir.c_str())) {
    while (dirent* e = readdir(d)) {
      std::string n = e->d_name;
      if (n != "." && n != "..") out.push_back(n);
    }
    closedir(d);
  }
  return out;
}

/// True when some process holds an flock on path (as Fast DDS's owners do);
/// if_unknown when the file cannot be opened.
bool locked(const std::string& path, bool if_unknown = true) {
  int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return if_unknown;  // cannot tell (cleaning: leave it)
  bool held = flock(fd, LOCK_EX | LOCK_NB) != 0;
  if (!held) flock(fd, LOCK_UN);
  close(fd);
  return held;
}

/// Every file under dir that some live process maps.
std::set<std::string> mapped_files(const std::string& dir) {
  std::set<std::string> out;
  const std::string prefix = dir + "/";
  for (const auto& pid : list_dir("/proc")) {
    if (pid.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream maps("/proc/" + pid + "/maps");
    std::string line;
    while (std::getline(maps, line)) {
      auto at = line.find(prefix);
      if (at == std::string::npos) continue;
      std::string path = line.substr(at);
      if (ends_with(path, " (deleted)")) continue;
      out.insert(path.substr(prefix.size()));
    }
  }
  return out;
}

void remove(const std::string& dir, const std::string& name, ShmCleanReport& r) {
  const std::string path = dir + "/" + name;
  struct stat st {};
  if (stat(path.c_str(), &st) != 0) return;
  if (unlink(path.c_str()) == 0) {
    ++r.files_removed;
    r.bytes_freed += static_cast<std::uint64_t>(st.st_blocks) * 512u;
    r.removed.push_back(name);
  }
}

/// True when path was modified less than min_age_s ago (or cannot be read:
/// leave it).
bool young(const std::string& path, double min_age_s) {
  struct stat st {};
  if (stat(path.c_str(), &st) != 0) return true;
  timespec now{};
  clock_gettime(CLOCK_REALTIME, &now);
  const double age = static_cast<double>(now.tv_sec - st.st_mtim.tv_sec) +
                     static_cast<double>(now.tv_nsec - st.st_mtim.tv_nsec) * 1e-9;
  return age < min_age_s;
}

/// A transport segment, port or data-sharing pool, and a port's mutex with it.
void remove_segment(const std::string& dir, const std::string& name, ShmCleanReport& r) {
  remove(dir, name, r);
  if (starts_with(name, "fastrtps_port")) remove(dir, "sem." + name + "_mutex", r);
}

}  // namespace

std::string ShmCleanReport::removed_names(std::size_t first) const {
  std::string out;
  for (std::size_t i = 0; i < removed.size() && i < first; ++i) out += (i ? ", " : "") + removed[i];
  if (removed.size() > first) out += " and " + std::to_string(removed.size() - first) + " more";
  return out;
}

ShmCleanReport clean_zombie_shm(const std::string& dir, double min_age_s) {
  ShmCleanReport r;
  const auto names = list_dir(dir);
  const std::set<std::string> present(names.begin(), names.end());
  std::set<std::string> mapped;
  bool have_mapped = false;
  const auto is_mapped = [&](const std::string& name) {
    if (!have_mapped) {
      mapped = mapped_files(dir);
      have_mapped = true;
    }
    return mapped.count(name) > 0;
  };
  for (const auto& n : names) {
    if (starts_with(n, "fastrtps_") && (ends_with(n, "_el") || ends_with(n, "_sl"))) {
      // A transport segment or port and its lock. Its owner alive <=> lock
      // held; but a dead owner's port is still mapped by the live processes
      // that send to it, and a restarted owner must reopen that same file
      // (unlinked, the senders would push into a file nobody reads).
      const std::string base = n.substr(0, n.size() - 3);
      if (locked(dir + "/" + n) || is_mapped(base)) {
        ++r.in_use;
        continue;
      }
      if (young(dir + "/" + n, min_age_s) ||
          (present.count(base) && young(dir + "/" + base, min_age_s))) {
        ++r.spared;
        continue;
      }
      remove(dir, n, r);
      remove_segment(dir, base, r);
    } else if ((starts_with(n, "fastrtps_port") && !present.count(n + "_el") &&
                !present.count(n + "_sl")) ||
               starts_with(n, "fast_datasharing_")) {
      // No lock tells whether these are in use, only a mapping does. A port
      // whose owner closed or died takes its lock file along: Fast DDS 2.9
      // leaves the port itself while a sender still counts on it (one file
      // per SIGKILLed sender, so they pile up by the thousand in /dev/shm on
      // a machine that runs the tests). A data-sharing pool never has a lock.
      if (is_mapped(n)) {
        ++r.in_use;
        continue;
      }
      if (young(dir + "/" + n, min_age_s)) {
        ++r.spared;
        continue;
      }
      remove_segment(dir, n, r);
    }
  }
  return r;
}

int participant_id_clear_of_shm(int domain_id, int max_id, const std::string& dir, int first_id) {
  // A port file, or its owner's lock without the file: a live process whose
  // port Fast DDS removed and never made anew (a sender's "Zombie. Reset the
  // port" after a stall) still listens there, and a newcomer on that id cannot
  // take its lock: it comes up without ports and never hears a scene
  // (docs/dds.md).
  auto held = [&](int port) {
    const std::string path = dir + "/fastrtps_port" + std::to_string(port);
    struct stat st;
    return stat(path.c_str(), &st) == 0 || locked(path + "_el", false);
  };
  for (int id = first_id; id <= max_id; ++id) {
    const int meta = rtps_unicast_port(domain_id, id);
    if (!held(meta) && !held(meta + 1)) return id;
  }
  return -1;
}

bool domain_has_live_participants(int domain_id, const std::string& dir) {
  // Every participant's shared-memory ports lie in its domain's block of 250
  // RTPS ports; a live owner holds its port's "_el" lock (see above).
  const int lo = rtps_port_base(domain_id), hi = lo + 250;
  for (const auto& n : list_dir(dir)) {
    int port = 0;
    char tail[4] = {};
    if (std::sscanf(n.c_str(), "fastrtps_port%d%3s", &port, tail) == 2 &&
        std::strcmp(tail, "_el") == 0 && port >= lo && port < hi && locked(dir + "/" + n, false))
      return true;
  }
  return false;
}

}  // namespace ddswarm
