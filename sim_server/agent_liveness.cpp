#include "sim_server/agent_liveness.hpp"

namespace ddswarm::sim {

double agent_silence_limit(double now_s, double newest_heard_s, double agent_timeout_s) {
  return now_s - newest_heard_s > kSilentSwarmShare * agent_timeout_s
             ? kSilentSwarmTimeouts * agent_timeout_s
             : agent_timeout_s;
}

double SwarmSilence::limit(double now_s, double newest_heard_s, double agent_timeout_s) {
  const double t = agent_silence_limit(now_s, newest_heard_s, agent_timeout_s);
  const bool silent = t > agent_timeout_s;
  if (silent_ && !silent) heard_again_s_ = now_s;
  silent_ = silent;
  return t;
}

bool declare_lost_now(int past_limit, double longest_silence_s, double limit_s) {
  return past_limit <= 1 || longest_silence_s > limit_s + kPortLockTimeoutS;
}

}  // namespace ddswarm::sim
