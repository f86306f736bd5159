#include "common/shm_clean.hpp"

#include "common/dds_config.hpp"
#include "common/participant.hpp"
#include "common/process.hpp"
#include "common/shm_test_dir.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <ctime>
#include <fstream>
#include <string>

using ddswarm::clean_zombie_shm;

namespace {

using ddswarm::test_util::TempDir;

/// Maps a file as a live process that uses it does (listed in /proc/self/maps).
struct Mapping {
  int fd;
  void* m = MAP_FAILED;
  explicit Mapping(const std::string& path) : fd(open(path.c_str(), O_RDWR)) {
    if (fd >= 0) m = mmap(nullptr, 4096, PROT_READ, MAP_SHARED, fd, 0);
  }
  ~Mapping() {
    if (m != MAP_FAILED) munmap(m, 4096);
    if (fd >= 0) close(fd);
  }
  bool ok() const { return m != MAP_FAILED; }
};

}  // namespace

TEST(ShmClean, RemovesTransportSegmentsAndPortsWhoseOwnerIsGone) {
  TempDir d;
  d.touch("fastrtps_0123456789abcdef");
  d.touch("fastrtps_0123456789abcdef_el", 0);
  d.touch("fastrtps_port7411");
  d.touch("fastrtps_port7411_el", 0);
  d.touch("sem.fastrtps_port7411_mutex", 32);
  d.touch("unrelated_file");
  auto r = clean_zombie_shm(d.path, 0.0);
  EXPECT_EQ(r.files_removed, 5);
  EXPECT_GT(r.bytes_freed, 0u);
  EXPECT_FALSE(d.has("fastrtps_0123456789abcdef"));
  EXPECT_FALSE(d.has("fastrtps_port7411"));
  EXPECT_FALSE(d.has("sem.fastrtps_port7411_mutex"));
  EXPECT_TRUE(d.has("unrelated_file")) << "only Fast DDS's files are touched";
}

TEST(ShmClean, KeepsWhatALiveProcessHolds) {
  TempDir d;
  d.touch("fastrtps_00000000000000aa");
  std::string lock = d.touch("fastrtps_00000000000000aa_el", 0);
  int fd = open(lock.c_str(), O_RDONLY);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(flock(fd, LOCK_EX), 0);  // as the owning participant does while it lives

  Mapping seg(d.touch("fast_datasharing_01.0f.00.00.00.00.00.00.00.00.00.00_0.0.1.4"));
  ASSERT_TRUE(seg.ok());
  d.touch("fast_datasharing_01.0f.00.00.00.00.00.00.00.00.00.01_0.0.1.4");  // nobody maps it

  auto r = clean_zombie_shm(d.path, 0.0);
  EXPECT_TRUE(d.has("fastrtps_00000000000000aa"));
  EXPECT_TRUE(d.has("fastrtps_00000000000000aa_el"));
  EXPECT_TRUE(d.has("fast_datasharing_01.0f.00.00.00.00.00.00.00.00.00.00_0.0.1.4"));
  EXPECT_FALSE(d.has("fast_datasharing_01.0f.00.00.00.00.00.00.00.00.00.01_0.0.1.4"));
  EXPECT_EQ(r.files_removed, 1);
  EXPECT_EQ(r.in_use, 2);
  close(fd);
}

TEST(ShmClean, KeepsADeadOwnersPortThatLiveSendersStillMap) {
  // A killed server's port: nobody holds its lock, but the agents that send to
  // it still map it, and the restarted server must reopen that same file.
  TempDir d;
  Mapping port(d.touch("fastrtps_port7413"));
  ASSERT_TRUE(port.ok());
  d.touch("fastrtps_port7413_el", 0);
  auto r = clean_zombie_shm(d.path, 0.0);
  EXPECT_TRUE(d.has("fastrtps_port7413"));
  EXPECT_TRUE(d.has("fastrtps_port7413_el"));
  EXPECT_EQ(r.files_removed, 0);
  EXPECT_EQ(r.in_use, 1);
}

// A port whose owner has gone with its lock file, left because a sender
// still counted on it: removed with its mutex once nobody maps it.
TEST(ShmClean, RemovesAPortWithoutAnOwnerOrASender) {
  TempDir d;
  d.touch("fastrtps_port7415");
  d.touch("sem.fastrtps_port7415_mutex", 32);
  Mapping sent_to(d.touch("fastrtps_port7417"));  // a live sender still maps this one
  ASSERT_TRUE(sent_to.ok());
  auto r = clean_zombie_shm(d.path, 0.0);
  EXPECT_FALSE(d.has("fastrtps_port7415"));
  EXPECT_FALSE(d.has("sem.fastrtps_port7415_mutex"));
  EXPECT_TRUE(d.has("fastrtps_port7417"));
  EXPECT_EQ(r.files_removed, 2);
  EXPECT_EQ(r.in_use, 1);
}

// A participant starting beside the clean-up has made its files but not yet
// locked or mapped them: they look like a dead process's, and removing them
// would cut it off its swarm. Only files older than the minimum age may go.
TEST(ShmClean, LeavesFilesBeingMadeToTheirMaker) {
  TempDir d;
  const std::string names[] = {"fastrtps_port7419", "fastrtps_port7419_el",
                               "fast_datasharing_01.0f.00.00.00.00.00.00.00.00.00.02_0.0.1.4"};
  for (const auto& n : names) d.touch(n);
  auto r = clean_zombie_shm(d.path);
  for (const auto& n : names) EXPECT_TRUE(d.has(n)) << n;
  EXPECT_EQ(r.files_removed, 0);
  EXPECT_EQ(r.spared, 2);  // the port with its lock, and the pool

  // The same files once they are older than the minimum age: zombies.
  const timespec past[2] = {{time(nullptr) - 10, 0}, {time(nullptr) - 10, 0}};
  for (const auto& n : names)
    ASSERT_EQ(utimensat(AT_FDCWD, (d.path + "/" + n).c_str(), past, 0), 0);
  r = clean_zombie_shm(d.path);
  for (const auto& n : names) EXPECT_FALSE(d.has(n)) << n;
  EXPECT_EQ(r.files_removed, 3);
  EXPECT_EQ(r.removed.size(), 3u);
  EXPECT_EQ(r.removed_names(1), r.removed[0] + " and 2 more");
  EXPECT_EQ(r.removed_names(6), r.removed[0] + ", " + r.removed[1] + ", " + r.removed[2]);
}

// A server restarted after a SIGKILL must not come up on its dead
// predecessor's ports, which the agents still map and write into.
TEST(ShmClean, ParticipantIdClearOfPortsADeadProcessLeft) {
  using ddswarm::participant_id_clear_of_shm;
  using ddswarm::rtps_unicast_port;
  TempDir d;
  const int domain = 42;
  EXPECT_EQ(participant_id_clear_of_shm(domain, 119, d.path), 0);
  // Id 0's metatraffic port (the dead server's), id 1's user-data port (a live agent's).
  d.touch("fastrtps_port" + std::to_string(rtps_unicast_port(domain, 0)));
  d.touch("fastrtps_port" + std::to_string(rtps_unicast_port(domain, 1) + 1));
  // Another domain's ports and other files do not count.
  d.touch("fastrtps_port" + std::to_string(rtps_unicast_port(domain + 1, 2)));
  d.touch("fastrtps_" + std::to_string(rtps_unicast_port(domain, 2)));
  EXPECT_EQ(participant_id_clear_of_shm(domain, 119, d.path), 2);
  EXPECT_EQ(participant_id_clear_of_shm(domain, 1, d.path), -1);  // every id up to max_id is held
  // From a first id on: 1 is held, 2 is clear.
  EXPECT_EQ(participant_id_clear_of_shm(domain, 119, d.path, 1), 2);
  EXPECT_EQ(participant_id_clear_of_shm(domain, 119, d.path, 3), 3);
}

// A live participant whose port file was removed (Fast DDS 2.9 makes it anew
// and removes it again after a stall) still holds its port's lock: a
// newcomer on that id cannot take the lock, comes up without ports and
// never hears the scene. A lock file nobody holds (its owner died) does not count.
TEST(ShmClean, ParticipantIdClearOfALiveOwnerWhosePortFileWasRemoved) {
  using ddswarm::participant_id_clear_of_shm;
  using ddswarm::rtps_unicast_port;
  TempDir d;
  const int domain = 43;
  const std::string el0 =
      d.touch("fastrtps_port" + std::to_string(rtps_unicast_port(domain, 0)) + "_el");
  d.touch("fastrtps_port" + std::to_string(rtps_unicast_port(domain, 1)) + "_el");  // stale
  EXPECT_EQ(participant_id_clear_of_shm(domain, 119, d.path), 0) << "no lock held yet";
  const int fd = ::open(el0.c_str(), O_RDONLY | O_CLOEXEC);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);  // the live owner's lock
  EXPECT_EQ(participant_id_clear_of_shm(domain, 119, d.path), 1);
  ::close(fd);
  EXPECT_EQ(participant_id_clear_of_shm(domain, 119, d.path), 0);
}

// A domain is in use while a Fast DDS participant of this host is on it
// (its shared-memory ports are locked), and not after.
TEST(ShmClean, ALiveParticipantMarksItsDomainInUse) {
  ddswarm::DdsConfig cfg;
  cfg.domain_id = 170 + static_cast<int>(ddswarm::random_instance() % 50);
  if (ddswarm::domain_has_live_participants(cfg.domain_id))
    GTEST_SKIP() << "domain " << cfg.domain_id << " is in use by another test";
  {
    ddswarm::Participant p(cfg, "shm_clean_test");
    if (!p.shared_memory()) GTEST_SKIP() << "no shared-memory transport in this build";
    EXPECT_TRUE(ddswarm::domain_has_live_participants(cfg.domain_id));
  }
  EXPECT_FALSE(ddswarm::domain_has_live_participants(cfg.domain_id));
}
