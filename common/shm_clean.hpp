#pragma once
// Removes the shared-memory files that crashed Fast DDS processes leave in
// /dev/shm, as `fastdds shm clean` does, plus the data-sharing segments that
// tool does not know. A killed process cannot unlink its segments; enough of
// them fill /dev/shm and break the next run.
//
// A file is a zombie only when no live process can be using it:
//   fastrtps_<id> / fastrtps_port<N> (SHM transport): their "_el"/"_sl" lock
//     file is not flock()ed by anyone (the owner holds it while alive) and
//     no process maps the file (senders map a port whose owner died);
//   fastrtps_port<N> without a lock file (its owner gone): no process maps it;
//   fast_datasharing_<guid>_<entity> (data-sharing pools): no process maps it
//     (/proc/*/maps).
// Files in use by any live process, of any domain or user, are never touched.
// Nor is a file younger than min_age_s: a participant starting meanwhile has
// made its segment, port or lock file but not yet mapped or locked it, and
// would lose it (a launcher starts the server and its agents together).
#include <cstdint>
#include <string>
#include <vector>

namespace ddswarm {

struct ShmCleanReport {
  int files_removed = 0;
  std::uint64_t bytes_freed = 0;
  int in_use = 0;  ///< segments and ports left alone because a live process holds them
  int spared = 0;  ///< unused by every sign but younger than min_age_s: left (maybe being made)
  std::vector<std::string> removed;  ///< the files' names

  /// The first `first` names removed, comma-separated, then "and K more".
  std::string removed_names(std::size_t first) const;
};

/// How old a file must be (by its mtime) before it may be a zombie. Fast DDS
/// makes a file and maps or locks it within microseconds; seconds leave a
/// loaded machine room.
inline constexpr double kShmZombieMinAgeS = 2.0;

/// Cleans dir (default /dev/shm). Never throws; unreadable entries are skipped.
ShmCleanReport clean_zombie_shm(const std::string& dir = "/dev/shm",
                                double min_age_s = kShmZombieMinAgeS);

/// The lowest participant id in [first_id, max_id] whose two RTPS unicast ports in
/// domain_id (metatraffic and user data) have no shared-memory port file in
/// dir, or -1 when every one has. A port file left by a process that died
/// (a killed server) is still mapped by the processes that sent to it, and
/// Fast DDS 2.9 keeps them writing into it after a new process re-creates the
/// port under the same name: nothing they send reaches the newcomer
/// (docs/dds.md). A newcomer on a clear id gets ports nobody holds. A port
/// whose file is gone while its owner still holds its "_el" lock is held too.
int participant_id_clear_of_shm(int domain_id, int max_id, const std::string& dir = "/dev/shm",
                                int first_id = 0);

/// True when some live process on this host has Fast DDS shared-memory ports
/// open in domain_id (a participant of any tool). Participants with the
/// shared-memory transport off do not show.
bool domain_has_live_participants(int domain_id, const std::string& dir = "/dev/shm");

}  // namespace ddswarm
