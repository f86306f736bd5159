#include "sim_server/agent_liveness.hpp"

namespace ddswarm::sim {

double agent_silence_limit(double now_s, double newest_heard_s, double agent_timeout_s) {
  return now_s - newest_heard_s > kSilentSwarmShare * agent_timeout_s
             ? kSilentSwarmTimeouts * agent_timeout_s
             : agent_timeout_s;
}

}  // namespace ddswarm::sim
