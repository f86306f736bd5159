#include "agent/join_watch.hpp"

#include <gtest/gtest.h>

namespace ddswarm::agent {
namespace {

constexpr double kNever = -1e9;

JoinPatience patience() {
  JoinPatience p;
  p.lease_s = 3;
  p.scene_wait_s = 40;
  p.handshake_timeout_s = 10;
  p.handshake_wait_s = 10;
  return p;
}

/// A drone flying at t = 100 s: joined at 0, scene at 1 s, the server's
/// scene writer matched since 0.5 s, a swarm state 20 ms ago.
JoinView flying() {
  JoinView v;
  v.now_s = 100;
  v.joined_s = 0;
  v.has_scene = true;
  v.last_state_s = 99.98;
  v.scene_s = 1;
  v.scene_writer_matched = true;
  v.scene_matched_since_s = 0.5;
  v.servers = {{true, 99.5, -1}};
  return v;
}

/// Just joined at t = 0, nothing heard yet.
JoinView joining(double now_s) {
  JoinView v;
  v.now_s = now_s;
  v.joined_s = 0;
  v.scene_s = kNever;
  return v;
}

TEST(JoinWatch, AFlyingDroneKeepsItsParticipant) {
  EXPECT_FALSE(why_join_again(flying(), patience()));
  JoinView waiting = joining(39.9);  // no server yet, within the scene wait
  EXPECT_FALSE(why_join_again(waiting, patience()));
}

// mp_fault_server_freeze: the server was stopped longer than the agent's
// lease and dropped it; its samples mark drone 7 agent-less while the agent
// answers them.
TEST(JoinWatch, AnUnheardDroneEndsTheJoinAfterTwiceTheLease) {
  JoinView v = flying();
  v.unheard_since = {{7, 94.0}};  // 6.0 s: exactly twice the lease, not more
  EXPECT_FALSE(why_join_again(v, patience()));
  v.unheard_since = {{3, 99.0}, {7, 93.9}};  // an agent host: the other drone is young
  const auto verdict = why_join_again(v, patience());
  ASSERT_TRUE(verdict);
  EXPECT_EQ(verdict->end, JoinEnd::kUnheard);
  EXPECT_EQ(verdict->why,
            "the server's samples have marked drone 7 agent-less for 6.1 s while this agent "
            "answered them: the server does not hear this agent; leaving DDS and joining again "
            "as a new participant");
}

// mp_fault_deaf_agent: the server's scene writer is matched, its swarm state
// does not come.
TEST(JoinWatch, NoSwarmStateFromAMatchedServerIsDeafness) {
  JoinView v = flying();
  v.last_state_s = 94.5;  // 5.5 s of silence: within twice the lease
  EXPECT_FALSE(why_join_again(v, patience()));
  v.last_state_s = 93.8;
  auto verdict = why_join_again(v, patience());
  ASSERT_TRUE(verdict);
  EXPECT_EQ(verdict->end, JoinEnd::kDeaf);
  EXPECT_EQ(verdict->why,
            "no swarm state from the server for 6.2 s while its scene writer is still matched: "
            "this participant does not hear the server; leaving DDS and joining again as a new "
            "participant");
  // Under DDS Security the swarm state's key exchange follows the scene's:
  // the wait is agent.handshake_timeout_s when that is longer.
  v.secure = true;
  EXPECT_FALSE(why_join_again(v, patience()));
  v.last_state_s = 89.9;
  ASSERT_TRUE(why_join_again(v, patience()));
  EXPECT_EQ(why_join_again(v, patience())->end, JoinEnd::kDeaf);
}

// A server stopped longer than its lease comes back: its writers match again
// a moment before its states come, so the count starts at the new match.
TEST(JoinWatch, AServerMatchedAgainIsGivenTimeForItsStates) {
  JoinView v = flying();
  v.last_state_s = 60;  // silent for 40 s while it was stopped
  v.scene_matched_since_s = 99;
  EXPECT_FALSE(why_join_again(v, patience()));
  // Unmatched (its lease ran out), silence alone is no deafness: the server is gone.
  v.scene_writer_matched = false;
  v.scene_matched_since_s = kNever;
  v.server_lost = true;
  EXPECT_FALSE(why_join_again(v, patience()));
}

// mp_fault_server_restart in CI (2026-11-29): the server was SIGKILLed and a
// new one started; agent 2 heard the new one announce itself and nothing else.
TEST(JoinWatch, ANewServerHeardOnlyByItsAnnouncementIsDeafness) {
  JoinView v = flying();
  v.server_lost = true;
  v.scene_writer_matched = false;
  v.last_state_s = 93.8;                             // the old server: silent for 6.2 s
  v.servers = {{true, 110, -1}, {false, 16.2, -1}};  // the dead one, within its lease; the new one
  auto verdict = why_join_again(v, patience());
  ASSERT_TRUE(verdict);
  EXPECT_EQ(verdict->end, JoinEnd::kDeaf);
  EXPECT_EQ(verdict->why,
            "a new server announced itself 16.2 s ago, the last one has been silent for 6.2 s, "
            "and no scene came from the new one: this participant does not hear it; leaving DDS "
            "and joining again as a new participant");
  // Announced only 5 s ago: its scene may still be on its way.
  v.servers[1].announced_s = 5;
  EXPECT_FALSE(why_join_again(v, patience()));
  // The old one silent only 5 s: silence is judged over twice the lease, as
  // for any deafness (a server paused for a moment is not gone).
  v.servers[1].announced_s = 16.2;
  v.last_state_s = 95;
  EXPECT_FALSE(why_join_again(v, patience()));
  // Only the old server listed: it is the one whose scene this agent flies.
  v.last_state_s = 80;
  v.servers = {{true, 110, -1}};
  EXPECT_FALSE(why_join_again(v, patience()));
}

// mp_secure_handshake_stall: Fast DDS 2.9 left the handshake with the server
// pending for good.
TEST(JoinWatch, ASecureHandshakeThatDoesNotEndIsAStall) {
  JoinView v = joining(12);
  v.secure = true;
  v.servers = {{false, 10.5, -1}};
  auto verdict = why_join_again(v, patience());
  ASSERT_TRUE(verdict);
  EXPECT_EQ(verdict->end, JoinEnd::kHandshakeStall);
  EXPECT_EQ(verdict->why,
            "the server announced itself 10.5 s ago and its authentication handshake with this "
            "participant has not ended; leaving DDS and joining again as a new participant");
  v.servers[0].announced_s = 9.5;  // within agent.handshake_timeout_s
  EXPECT_FALSE(why_join_again(v, patience()));
  v.servers[0].announced_s = 10.5;
  v.servers[0].authenticated_after_s = 1.2;  // authenticated; the scene may take longer
  EXPECT_FALSE(why_join_again(v, patience()));
  // A restarted server's predecessor authenticated us; the new one has not.
  v.servers.push_back({false, 11, -1});
  ASSERT_TRUE(why_join_again(v, patience()));
  EXPECT_EQ(why_join_again(v, patience())->end, JoinEnd::kHandshakeStall);
  // Without Security, or with the rule off, a pending handshake means nothing.
  v.secure = false;
  EXPECT_FALSE(why_join_again(v, patience()));
  v.secure = true;
  JoinPatience off = patience();
  off.handshake_wait_s = 0;
  EXPECT_FALSE(why_join_again(v, off));
}

TEST(JoinWatch, NoSceneWithinTheWaitEndsTheJoinUnlessTheWaitIsOff) {
  auto verdict = why_join_again(joining(40.1), patience());
  ASSERT_TRUE(verdict);
  EXPECT_EQ(verdict->end, JoinEnd::kNoScene);
  EXPECT_EQ(verdict->why,
            "no scene within 40.0 s (no server announced itself to this participant); leaving "
            "DDS and joining again as a new participant");
  // What it heard tells discovery, the handshake and the scene's writer apart.
  JoinView heard = joining(40.1);
  heard.secure = true;
  heard.servers = {{false, 2.0, 0.5}, {false, 38.0, 1.5}};
  EXPECT_EQ(why_join_again(heard, patience())->why,
            "no scene within 40.0 s (a server announced itself 38.0 s ago and authenticated it "
            "1.5 s later; its scene writer is not matched); leaving DDS and joining again as a "
            "new participant");
  heard.secure = false;
  heard.scene_writer_matched = true;
  EXPECT_EQ(why_join_again(heard, patience())->why,
            "no scene within 40.0 s (a server announced itself 38.0 s ago; its scene writer is "
            "matched); leaving DDS and joining again as a new participant");
  JoinPatience off = patience();
  off.scene_wait_s = 0;  // agent.rejoin_after_s: 0
  EXPECT_FALSE(why_join_again(joining(1e6), off));
  // Once the scene came, the scene wait is over for this join.
  JoinView v = flying();
  v.now_s = 1e6;
  v.last_state_s = 1e6 - 0.02;
  EXPECT_FALSE(why_join_again(v, patience()));
}

// 128 processes in real time on 2 cores (2026-11-30): the server stalls for
// a second now and then. Remaking every agent's swarm-state reader at each
// stall fed it, and now and then a new reader met a Fast DDS assertion.
TEST(JoinWatch, ASlowServerKeepsItsReadersAGoneOneDoesNot) {
  JoinView v = flying();
  v.last_state_s = 98.8;
  EXPECT_FALSE(lost_server_gone(v)) << "not lost yet";
  v.server_lost = true;
  EXPECT_FALSE(lost_server_gone(v)) << "silent, its scene writer still matched: slow";
  v.scene_writer_matched = false;  // its lease ran out
  EXPECT_TRUE(lost_server_gone(v));
  v.scene_writer_matched = true;  // SIGKILLed, and a new one announced within the lease
  v.servers.push_back({false, 0.5, -1});
  EXPECT_TRUE(lost_server_gone(v));
}

// The rules in the order docs/faults.md gives: the most specific first, so
// the log names the cause a user can act on.
TEST(JoinWatch, TheMostSpecificRuleSpeaks) {
  JoinView v = flying();
  v.unheard_since = {{2, 90}};
  v.last_state_s = 90;  // deaf too
  EXPECT_EQ(why_join_again(v, patience())->end, JoinEnd::kUnheard);
  JoinView stalled = joining(45);  // past the scene wait and the handshake wait
  stalled.secure = true;
  stalled.servers = {{false, 44, -1}};
  EXPECT_EQ(why_join_again(stalled, patience())->end, JoinEnd::kHandshakeStall);
}

}  // namespace

// The 64-drone soak: a new server stalled 3.3 s as it started; agents that
// lost it had the scene, the server's scene writer unmatched, no other
// server, and stayed unheard for 5 minutes. After 20 leases (60 s) a new
// participant looks for it; a shorter silence, or one with another server
// coming, is left to the other rules.
TEST(JoinWatch, ALostServerSilentAndUnmatchedForLongIsLookedForAfresh) {
  JoinView v = flying();
  v.server_lost = true;
  v.scene_writer_matched = false;
  v.last_state_s = 100 - 59.9;
  EXPECT_FALSE(why_join_again(v, patience()));
  v.last_state_s = 100 - 60.1;
  const auto verdict = why_join_again(v, patience());
  ASSERT_TRUE(verdict);
  EXPECT_EQ(verdict->end, JoinEnd::kDeaf);
  EXPECT_NE(verdict->why.find("the server has been silent for 60.1 s"), std::string::npos)
      << verdict->why;
  JoinView matched = v;  // still matched: the deaf-to-a-live-server rule's, after 6 s
  matched.scene_writer_matched = true;
  ASSERT_TRUE(why_join_again(matched, patience()));
  EXPECT_EQ(why_join_again(matched, patience())->why.find("the server has been silent"),
            std::string::npos);
  JoinPatience never = patience();  // agent.rejoin_after_s: 0, never
  never.scene_wait_s = 0;
  EXPECT_FALSE(why_join_again(v, never));
  JoinPatience slow = patience();  // a longer scene wait is the longer wait
  slow.scene_wait_s = 90;
  EXPECT_FALSE(why_join_again(v, slow));
}

}  // namespace ddswarm::agent
