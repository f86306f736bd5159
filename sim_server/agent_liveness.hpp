#pragma once
// When the server declares an agent lost: a pure rule, free of DDS and clocks.

namespace ddswarm::sim {

/// While no live agent at all has been heard for this share of
/// agent_timeout_s, an agent is declared lost only after kSilentSwarmTimeouts
/// timeouts. Every live agent sends a heartbeat 4 times a second.
constexpr double kSilentSwarmShare = 0.5;
constexpr double kSilentSwarmTimeouts = 3.0;

/// How long (wall s) a live agent may stay silent before the server declares
/// it lost: agent_timeout_s, or kSilentSwarmTimeouts times that while every
/// live agent has been silent for kSilentSwarmShare of it, since then the
/// silence may be the server's own. Fast DDS can stall its receive threads
/// for over a second while it drops a killed agent's participant, and with a
/// plain timeout every other agent would be declared lost with it. In
/// mp_fault_agent_kill the agent heard longest ago, 1 s before, can pass the
/// timeout with the killed one and be back 9 ms later (likely the killed agent
/// holds the server's shared-memory port lock, which Fast DDS waits 1 s for;
/// docs/faults.md).
/// newest_heard_s: when any live agent was last heard.
double agent_silence_limit(double now_s, double newest_heard_s, double agent_timeout_s);

/// A swarm-wide silence as the server's checks see it, one check after
/// another. When a live agent is heard again after one, the samples queued
/// behind its own come in over the next moments: every live agent's silence
/// then counts from that moment, not from its last word. In mp_fault_agent_kill
/// a 1 s stall of the server's port can end with two agents heard and the
/// three others back 4 ms later, which a count from their last word would
/// declare lost at that instant.
class SwarmSilence {
 public:
  /// Call at every check: the timeout that applies now (agent_silence_limit).
  /// newest_heard_s: when any live agent was last heard.
  double limit(double now_s, double newest_heard_s, double agent_timeout_s);
  /// True when the last check found the whole swarm silent.
  bool silent() const { return silent_; }
  /// From when an agent last heard at last_heard_s counts as silent.
  double silent_since(double last_heard_s) const {
    return last_heard_s > heard_again_s_ ? last_heard_s : heard_again_s_;
  }

 private:
  bool silent_ = false;
  double heard_again_s_ = -1e300;  ///< when the last swarm-wide silence ended
};

/// How long Fast DDS 2.9 waits for an interprocess lock before it gives up
/// (BOOST_INTERPROCESS_TIMEOUT_WHEN_LOCKING_DURATION_MS, 1000 ms in its
/// build): an agent killed while it held the lock of the server's
/// shared-memory port stalls every other agent's writes to it that long.
constexpr double kPortLockTimeoutS = 1.0;

/// Whether the agents past their silence limit at one check are declared
/// lost now: past_limit of them, the longest silent for longest_silence_s.
/// One alone is. Several at once are most likely one cause, their writes
/// stalled behind a killed agent's lock on the server's port, not as many
/// deaths: they wait until the longest silence passes the limit by
/// kPortLockTimeoutS. In mp_fault_agent_kill four live agents can pass the
/// 1 s limit with the killed one while a fifth keeps being heard (so the
/// swarm is never silent), and be back 1 ms later.
bool declare_lost_now(int past_limit, double longest_silence_s, double limit_s);

}  // namespace ddswarm::sim
