#pragma once
// When the server declares an agent lost: a pure rule, free of DDS and clocks.

namespace ddswarm::sim {

/// While no live agent at all has been heard within agent_timeout_s, an agent
/// is declared lost only after this many timeouts.
constexpr double kSilentSwarmTimeouts = 3.0;

/// How long (wall s) a live agent may stay silent before the server declares
/// it lost: agent_timeout_s, or kSilentSwarmTimeouts times that while every
/// live agent is silent, since then the silence may be the server's own (Fast
/// DDS stalled its receive threads for over a second while it dropped a killed
/// agent's participant, and every other agent was declared lost with it).
/// newest_heard_s: when any live agent was last heard.
double agent_silence_limit(double now_s, double newest_heard_s, double agent_timeout_s);

}  // namespace ddswarm::sim
