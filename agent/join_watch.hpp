#pragma once
// Whether an agent's participant should leave DDS and join again, and why,
// and whether a lost server is gone (its swarm-state reader is then made
// anew): the rules of docs/faults.md as pure functions of what the agent's
// run loop reads, free of DDS and clocks. AgentApp::run gathers the view under
// its lock and applies the verdict; agent/main.cpp's join loop, with
// RejoinPolicy, joins again.
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace ddswarm::agent {

/// How one join of an agent ended (AgentApp::End).
enum class JoinEnd {
  kStopped,          ///< stop requested, or the run's duration is over
  kNoScene,          ///< no scene within agent.rejoin_after_s of joining
  kRejoinRequested,  ///< SIGUSR1 (ddswarm-launch: its discovery server dropped us)
  kOutlivedLease,    ///< stopped or starved longer than the DDS lease
  kUnheard,          ///< the server's samples say it hears none of our answers
  kDeaf,             ///< we hear no swarm state from a server that is there
  kHandshakeStall,   ///< under DDS Security, the server's handshake did not end
};

/// A server participant that discovery lists (Participant::peers_named).
struct ServerPeer {
  bool current = false;    ///< the participant whose scene this agent flies
  double announced_s = 0;  ///< since its discovery data came
  /// Under DDS Security, how long after its announcement it authenticated
  /// this participant; < 0 while it has not (and always without Security).
  double authenticated_after_s = -1;
};

/// What the run loop knows at one turn. Times are wall seconds; "never" is
/// any time far in the past (the agent uses -1e9).
struct JoinView {
  double now_s = 0;
  double joined_s = 0;                ///< when this participant joined
  bool has_scene = false;             ///< a scene came (from the current server)
  bool server_lost = false;           ///< no server sample for agent.server_timeout_s since a tick
  double last_state_s = -1e9;         ///< the last swarm state taken
  double scene_s = -1e9;              ///< the scene's arrival
  bool scene_writer_matched = false;  ///< the server's scene writer is matched
  double scene_matched_since_s = -1e9;
  /// Drones of this process that the server's samples mark agent-less while
  /// this process answers them: id and since when.
  std::vector<std::pair<int, double>> unheard_since;
  std::vector<ServerPeer> servers;  ///< every live participant named ddswarm-sim
  bool secure = false;              ///< this participant uses DDS Security
};

/// How long each rule waits; this join's values (RejoinPolicy, spread by
/// process where AgentApp::run says so).
struct JoinPatience {
  double lease_s = 3;               ///< dds.lease_duration_s
  double scene_wait_s = 40;         ///< agent.rejoin_after_s, spread (0 = never)
  double handshake_timeout_s = 10;  ///< agent.handshake_timeout_s (0 = never)
  double handshake_wait_s = 10;     ///< the same, spread
  /// How long a swarm state may stay missing from a server that is there:
  /// twice the lease; under DDS Security at least handshake_timeout_s, since
  /// the swarm state's key exchange comes after the scene's.
  double deaf_s(bool secure) const;
  /// How long a lost server may stay silent and unmatched, with no other
  /// server in sight, before a new participant looks for it: the longer of
  /// scene_wait_s and 20 leases (60 s by default).
  double lost_server_s() const;
};

struct JoinVerdict {
  JoinEnd end;
  std::string why;  ///< one log line, without the agent's label
};

/// Whether the lost server is gone, not merely slow: its scene writer is no
/// longer matched (its lease ran out), or another server announced itself.
/// Then the agent makes its swarm-state reader anew, since a server SIGKILLed
/// while it notified that reader left the reader's lock held for good
/// (docs/faults.md). A slow server keeps its readers: remaking 128 of them at
/// every stall of a starved machine fed the stall (docs/performance.md).
bool lost_server_gone(const JoinView& v);

/// The first rule that ends this join, in the order docs/faults.md gives
/// ("Why an agent joins again"):
/// unheard, deaf to a live server, deaf to a new server, a lost server
/// silent and unmatched, a stalled secure handshake, no scene. nullopt: keep flying.
std::optional<JoinVerdict> why_join_again(const JoinView& v, const JoinPatience& p);

}  // namespace ddswarm::agent
