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
/// silence may be the server's own. Fast DDS stalled its receive threads for
/// over a second while it dropped a killed agent's participant, and every
/// other agent was declared lost with it. Once, in mp_fault_agent_kill, the
/// agent heard longest ago, 1 s before, was declared lost with the killed one
/// and was back 9 ms later (likely the killed agent held the server's
/// shared-memory port lock, which Fast DDS waits 1 s for; docs/faults.md).
/// newest_heard_s: when any live agent was last heard.
double agent_silence_limit(double now_s, double newest_heard_s, double agent_timeout_s);

}  // namespace ddswarm::sim
