#include "agent/join_watch.hpp"

#include <spdlog/fmt/fmt.h>

#include <algorithm>

namespace ddswarm::agent {

namespace {
constexpr const char* kJoinAgain = "leaving DDS and joining again as a new participant";

/// What a participant without a scene heard of servers: the words that tell
/// a user whether discovery, the handshake or the scene's writer is missing.
std::string what_was_heard(const JoinView& v) {
  if (v.servers.empty()) return "no server announced itself to this participant";
  const ServerPeer& s = *std::max_element(
      v.servers.begin(), v.servers.end(),
      [](const ServerPeer& a, const ServerPeer& b) { return a.announced_s < b.announced_s; });
  std::string heard = fmt::format("a server announced itself {:.1f} s ago", s.announced_s);
  if (v.secure)
    heard += s.authenticated_after_s >= 0
                 ? fmt::format(" and authenticated it {:.1f} s later", s.authenticated_after_s)
                 : std::string(" and has not authenticated it");
  heard += v.scene_writer_matched ? "; its scene writer is matched"
                                  : "; its scene writer is not matched";
  return heard;
}
}  // namespace

double JoinPatience::lost_server_s() const { return std::max(scene_wait_s, 20 * lease_s); }

double JoinPatience::deaf_s(bool secure) const {
  return secure ? std::max(2 * lease_s, handshake_timeout_s) : 2 * lease_s;
}

bool lost_server_gone(const JoinView& v) {
  if (!v.server_lost) return false;
  return !v.scene_writer_matched || std::any_of(v.servers.begin(), v.servers.end(),
                                                [](const ServerPeer& s) { return !s.current; });
}

std::optional<JoinVerdict> why_join_again(const JoinView& v, const JoinPatience& p) {
  // Hearing, but not heard: the server's samples say for a while that it has
  // no live agent for a drone this process answers for. Its reader lost this
  // participant one-sidedly (the server was stopped longer than this agent's
  // lease, or discovery dropped this participant's endpoints): a new
  // participant is discovered afresh.
  for (const auto& [id, since] : v.unheard_since) {
    const double unheard = v.now_s - since;
    if (unheard > 2 * p.lease_s)
      return JoinVerdict{JoinEnd::kUnheard,
                         fmt::format("the server's samples have marked drone {} agent-less for "
                                     "{:.1f} s while this agent answered them: the server does "
                                     "not hear this agent; {}",
                                     id, unheard, kJoinAgain)};
  }
  // Deaf to a live server: its scene writer is still matched, yet no swarm
  // state came for deaf_s. A live server publishes at least every 0.25 s
  // (lockstep resends, a paused swarm), and one stopped longer than its lease
  // is dropped with its writers, so this is a reader that lost or never
  // matched the server's swarm-state writer. The count starts again when the
  // server is matched again: one that was away longer than its lease comes
  // back a moment before its states.
  const double deaf_s = p.deaf_s(v.secure);
  if (v.has_scene && v.scene_writer_matched) {
    const double deaf = v.now_s - std::max({v.last_state_s, v.scene_s, v.scene_matched_since_s});
    if (deaf > deaf_s)
      return JoinVerdict{JoinEnd::kDeaf,
                         fmt::format("no swarm state from the server for {:.1f} s while its "
                                     "scene writer is still matched: this participant does not "
                                     "hear the server; {}",
                                     deaf, kJoinAgain)};
  }
  // Deaf to a new server: the old one went silent and another announced
  // itself, both deaf_s ago, yet no scene came from it. What it sends this
  // participant does not arrive, though its announcements do (over UDP): a
  // server SIGKILLed while it held the lock of this agent's shared-memory
  // port leaves every later message to that port lost. A new participant
  // listens on new ports.
  if (v.has_scene && v.server_lost) {
    const double silent_for = v.now_s - v.last_state_s;
    for (const auto& s : v.servers) {
      if (s.current || std::min(s.announced_s, silent_for) <= deaf_s) continue;
      return JoinVerdict{JoinEnd::kDeaf,
                         fmt::format("a new server announced itself {:.1f} s ago, the last one "
                                     "has been silent for {:.1f} s, and no scene came from the "
                                     "new one: this participant does not hear it; {}",
                                     s.announced_s, silent_for, kJoinAgain)};
    }
  }
  // Lost without a trace: the server went silent, its scene writer is no
  // longer matched and no other server came, for the longer of the scene
  // wait and 20 leases. A server that is really gone costs a re-join now and
  // then; one that is alive but that this participant no longer discovers
  // is found again only by a new participant. In the 64-drone soak a new
  // server stalled 3.3 s as it started, and 14 agents that lost it were not
  // heard for 5 minutes, until the next server came.
  if (v.has_scene && v.server_lost && !v.scene_writer_matched && p.scene_wait_s > 0) {
    const double silent_for = v.now_s - v.last_state_s;
    const bool other_server = std::any_of(v.servers.begin(), v.servers.end(),
                                          [](const ServerPeer& s) { return !s.current; });
    if (!other_server && silent_for > p.lost_server_s())
      return JoinVerdict{JoinEnd::kDeaf,
                         fmt::format("the server has been silent for {:.1f} s, its scene writer "
                                     "is not matched and no other server announced itself: a "
                                     "live server this participant no longer discovers is "
                                     "found by a new one; {}",
                                     silent_for, kJoinAgain)};
  }
  // Under DDS Security a server that announced itself authenticates this
  // participant within a second or two, at 16 drones too; its scene may take
  // longer (the scene wait covers that). Fast DDS 2.9 sometimes leaves a
  // handshake pending for good: a new participant starts every handshake
  // afresh. Any server counts: a restarted one's predecessor may still be
  // within its lease.
  if (!v.has_scene && v.secure && p.handshake_wait_s > 0) {
    for (const auto& s : v.servers) {
      if (s.authenticated_after_s >= 0 || s.announced_s <= p.handshake_wait_s) continue;
      return JoinVerdict{JoinEnd::kHandshakeStall,
                         fmt::format("the server announced itself {:.1f} s ago and its "
                                     "authentication handshake with this participant has not "
                                     "ended; {}",
                                     s.announced_s, kJoinAgain)};
    }
  }
  // Fast DDS 2.9 sometimes never matches one of 128 participants that start
  // at once (docs/performance.md); a new participant is discovered afresh.
  // No scene also means no mission to lose.
  if (!v.has_scene && p.scene_wait_s > 0 && v.now_s - v.joined_s > p.scene_wait_s)
    return JoinVerdict{JoinEnd::kNoScene,
                       fmt::format("no scene within {:.1f} s ({}); {}", p.scene_wait_s,
                                   what_was_heard(v), kJoinAgain)};
  return std::nullopt;
}

}  // namespace ddswarm::agent
