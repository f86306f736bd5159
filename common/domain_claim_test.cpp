// Two experiments on one host must not share a DDS domain: each claims its
// domains, and passes over any that another process claimed or that live
// participants use.
#include "common/domain_claim.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <unistd.h>

#include <fstream>
#include <string>

#include "common/shm_clean.hpp"
#include "common/shm_test_dir.hpp"

namespace ddswarm {
namespace {

using test_util::TempDir;

TEST(DomainClaim, ASecondClaimOfADomainFailsAndNamesItsHolder) {
  TempDir dir;
  std::string holder;
  {
    DomainClaim first(5, dir.path);
    ASSERT_TRUE(first.held()) << first.holder();
    DomainClaim second(5, dir.path);
    EXPECT_FALSE(second.held());
    holder = second.holder();
    EXPECT_TRUE(DomainClaim(6, dir.path).held()) << "another domain is free";
    DomainClaim moved = std::move(first);  // a claim moved keeps the domain
    EXPECT_TRUE(moved.held());
    EXPECT_FALSE(DomainClaim(5, dir.path).held());
  }
  EXPECT_NE(holder.find("pid " + std::to_string(getpid()) + ": "), std::string::npos) << holder;
  EXPECT_NE(holder.find("gs_domain_claim_test"), std::string::npos) << holder;
  EXPECT_TRUE(DomainClaim(5, dir.path).held()) << "the claim ends with its owner";
}

// A holder that could not write its note (a file another user made) leaves
// the last one's in place: a gone process is not named.
TEST(DomainClaim, AStaleNoteNamesNoOne) {
  TempDir dir;
  const std::string lock = dir.path + "/ddswarm_domain_7.lock";
  std::ofstream(lock) << "pid 2147483646: a launch long gone\n";
  const int fd = open(lock.c_str(), O_RDONLY);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(flock(fd, LOCK_EX | LOCK_NB), 0);
  DomainClaim c(7, dir.path);
  EXPECT_FALSE(c.held());
  EXPECT_EQ(c.holder(), "another process (" + lock + ")");
  close(fd);
  EXPECT_TRUE(DomainClaim(7, dir.path).held());
}

TEST(DomainClaim, FreeDomainsPassOverClaimedOnesAndOnesWithLiveParticipants) {
  TempDir dir;
  DomainClaim taken(3, dir.path);
  ASSERT_TRUE(taken.held());
  // A live participant on domain 4: its port's lock is held, as Fast DDS's
  // shared-memory transport holds it.
  const std::string port = "fastrtps_port" + std::to_string(7400 + 250 * 4 + 12);
  dir.touch(port);
  const int fd = open(dir.touch(port + "_el", 0).c_str(), O_RDONLY);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(flock(fd, LOCK_EX | LOCK_NB), 0);
  // A dead one's port on domain 5: its lock file is left, and no one holds it.
  dir.touch("fastrtps_port" + std::to_string(7400 + 250 * 5 + 10) + "_el", 0);

  std::vector<std::string> why;
  const auto got = claim_free_domains(3, 2, &why, dir.path);
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[0].domain(), 5);
  EXPECT_EQ(got[1].domain(), 6);
  ASSERT_EQ(why.size(), 2u);
  EXPECT_EQ(why[0].rfind("domain 3: pid ", 0), 0u) << why[0];
  EXPECT_EQ(why[1], "domain 4: DDS participants on this host use it");
  EXPECT_FALSE(DomainClaim(5, dir.path).held()) << "what was handed out stays claimed";

  close(fd);
  EXPECT_FALSE(domain_has_live_participants(4, dir.path)) << "its owner is gone";
  EXPECT_EQ(claim_free_domains(230, 5, nullptr, dir.path).size(), 3u) << "230..232, no further";
}

}  // namespace
}  // namespace ddswarm
