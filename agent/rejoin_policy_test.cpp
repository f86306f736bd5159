#include "agent/rejoin_policy.hpp"

#include <gtest/gtest.h>

namespace ddswarm::agent {
namespace {

// mp_fault_shm_port_removed: the server's port files are gone; agent 2, which
// had the scene, is asked to join again. Its next participant waits 4 leases,
// not 40 s, and when no scene comes, every later join talks UDP.
TEST(RejoinPolicy, AJoinAfterTheSceneThatHearsNoneLeavesSharedMemoryOut) {
  RejoinPolicy p(40.0, 3.0, true);
  EXPECT_DOUBLE_EQ(p.scene_wait_s(), 40.0);
  EXPECT_FALSE(p.ended(false, false, true));  // SIGUSR1 after flying with the scene
  EXPECT_DOUBLE_EQ(p.scene_wait_s(), 12.0);
  EXPECT_TRUE(p.shm_transport());
  EXPECT_TRUE(p.ended(false, true, false)) << "no scene right after the swarm was up";
  EXPECT_FALSE(p.shm_transport());
  // A server that is gone is then waited for as before: 40 s, doubling.
  EXPECT_DOUBLE_EQ(p.scene_wait_s(), 80.0);
  EXPECT_FALSE(p.ended(false, true, false)) << "said once";
  EXPECT_DOUBLE_EQ(p.scene_wait_s(), 160.0);
  EXPECT_FALSE(p.shm_transport());
}

// mp_fault_server_freeze in CI: the server did not hear the agent after its
// stop (kUnheard); the re-joined participant, on shared memory, heard no scene.
TEST(RejoinPolicy, AnUnheardOrDeafAgentJoinsWithoutSharedMemory) {
  RejoinPolicy p(40.0, 3.0, true);
  EXPECT_TRUE(p.ended(true, false, true));
  EXPECT_FALSE(p.shm_transport());
  EXPECT_DOUBLE_EQ(p.scene_wait_s(), 12.0);
  EXPECT_FALSE(p.ended(true, false, true)) << "said once";
}

// mp_fault_server_lock_kill: the agent whose lock the killed server held
// starts again as the same process. Its first join waited the start-up 40-60 s
// for the new server's scene, past the 60 s the test's ground station waits;
// it waits 4 leases, and when no scene comes, it joins again over UDP.
TEST(RejoinPolicy, AProcessStartedAgainWaitsLeasesForTheScene) {
  RejoinPolicy p(40.0, 3.0, true);
  p.started_again();
  EXPECT_DOUBLE_EQ(p.scene_wait_s(), 12.0);
  EXPECT_TRUE(p.shm_transport());
  EXPECT_TRUE(p.ended(false, true, false)) << "no scene from the new server";
  EXPECT_FALSE(p.shm_transport());
}

// At start-up (no scene yet) a join that heard none is a slow discovery, not
// a lost port: it keeps shared memory and waits twice as long each time.
TEST(RejoinPolicy, NoSceneAtStartUpKeepsSharedMemory) {
  RejoinPolicy p(40.0, 3.0, true);
  EXPECT_FALSE(p.ended(false, true, false));
  EXPECT_TRUE(p.shm_transport());
  EXPECT_DOUBLE_EQ(p.scene_wait_s(), 80.0);
  // Stopped longer than the lease after the scene: the next join waits 4 leases.
  EXPECT_FALSE(p.ended(false, false, true));
  EXPECT_DOUBLE_EQ(p.scene_wait_s(), 12.0);
}

// Never re-joining for want of a scene (agent.rejoin_after_s 0) stays so, and
// a configuration without the shared-memory transport has nothing to leave out.
TEST(RejoinPolicy, ZeroWaitAndNoSharedMemoryStayAsConfigured) {
  RejoinPolicy never(0.0, 3.0, true);
  EXPECT_FALSE(never.ended(false, false, true));
  EXPECT_DOUBLE_EQ(never.scene_wait_s(), 0.0);
  RejoinPolicy udp(40.0, 3.0, false);
  EXPECT_FALSE(udp.ended(true, false, true));
  EXPECT_FALSE(udp.shm_transport());
}

// mp_secure_handshake_stall: under DDS Security the server announced itself,
// yet its handshake with this participant never ended. The
// next join waits twice as long, and so on up to 8 times; any other end
// starts the count again. Such an end leaves the scene wait as it was.
TEST(RejoinPolicy, HandshakeStallsInARowWaitTwiceAsLongEachTime) {
  RejoinPolicy p(40.0, 3.0, false, 10.0);
  EXPECT_DOUBLE_EQ(p.handshake_wait_s(), 10.0);
  for (double want : {20.0, 40.0, 80.0, 80.0}) {
    EXPECT_FALSE(p.ended(false, false, false, true));
    EXPECT_DOUBLE_EQ(p.handshake_wait_s(), want);
    EXPECT_DOUBLE_EQ(p.scene_wait_s(), 40.0);
  }
  EXPECT_FALSE(p.ended(false, false, true));  // flew, then asked to join again
  EXPECT_DOUBLE_EQ(p.handshake_wait_s(), 10.0);
  RejoinPolicy never(40.0, 3.0, false);
  EXPECT_FALSE(never.ended(false, false, false, true));
  EXPECT_DOUBLE_EQ(never.handshake_wait_s(), 0.0);
}

// A large secure swarm's handshakes queue at the server: the timeout grows
// with the scenario's drones (0.75 s each), never below the configured value,
// and 0 (never) stays never.
TEST(RejoinPolicy, HandshakeTimeoutGrowsWithTheSwarm) {
  EXPECT_DOUBLE_EQ(handshake_timeout_for(10.0, 6), 10.0);
  EXPECT_DOUBLE_EQ(handshake_timeout_for(10.0, 64), 48.0);
  EXPECT_DOUBLE_EQ(handshake_timeout_for(10.0, 128), 96.0);
  EXPECT_DOUBLE_EQ(handshake_timeout_for(100.0, 128), 100.0);
  EXPECT_DOUBLE_EQ(handshake_timeout_for(0.0, 128), 0.0);
}

}  // namespace
}  // namespace ddswarm::agent
