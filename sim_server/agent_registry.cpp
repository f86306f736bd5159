#include "sim_server/agent_registry.hpp"

#include <algorithm>

namespace ddswarm::sim {

AgentRegistry::AgentRegistry(int drones, bool lockstep, Pipeline pipeline)
    : lockstep_(lockstep), slots_(static_cast<std::size_t>(drones)), barrier_(drones, pipeline) {}

CommandView AgentRegistry::view(int i) const {
  const AgentSlot& s = slots_[i];
  return {s.setpoint, s.has_command, s.command_tick, s.live};
}

bool AgentRegistry::adopt(AgentSlot& s, int id, std::uint64_t instance, double now_wall_s) {
  const bool was_live = s.live;
  if (!s.live) {
    s.live = true;
    s.owner = instance;
    barrier_.join(id);
  }
  s.last_heard_wall_s = now_wall_s;
  return !was_live;
}

AgentRegistry::Heard AgentRegistry::heartbeat(int id, std::uint64_t instance, double now_wall_s) {
  if (id < 0 || id >= size()) return Heard::kUnknownId;
  AgentSlot& s = slots_[id];
  if (s.live && s.owner != instance) return Heard::kImpostor;
  return adopt(s, id, instance, now_wall_s) ? Heard::kOnline : Heard::kHeard;
}

Verdict AgentRegistry::check(const CommandFacts& c, double max_speed_mps) const {
  const std::uint64_t published = barrier_.published();
  GateContext g{size(), published, 0, 0, max_speed_mps};
  if (c.drone_id >= 0 && c.drone_id < size()) {
    const AgentSlot& s = slots_[c.drone_id];
    g.owner_instance = s.live ? s.owner : 0;
    g.oldest_ok_tick = lockstep_ ? published : (s.has_command ? s.command_tick : 0);
    // An agent answers a tick published twice (run_lockstep) twice.
    if (lockstep_ && s.live && s.has_command) g.answered_tick = s.command_tick;
  }
  return check_command(c, g);
}

AgentRegistry::Recorded AgentRegistry::record(int id, std::uint64_t instance,
                                              const CommandRecord& c, double now_wall_s) {
  Recorded r;
  AgentSlot& s = slots_[id];
  r.online = adopt(s, id, instance, now_wall_s);
  r.status_due = r.online;
  s.setpoint = c.setpoint;
  s.has_command = true;
  s.command_tick = c.tick;
  if (c.mission_seq != s.mission_seq || c.mission_issuer != s.mission_issuer ||
      c.phase != s.phase) {
    s.mission_seq = c.mission_seq;
    s.mission_issuer = c.mission_issuer;
    r.status_due = true;
  }
  s.phase = c.phase;
  s.busy = c.busy;
  // Real time: an answer to a state older than the newest arrived after the
  // step it was meant for (it is still the freshest, so it is applied).
  // Pipelined, that step comes after the next state goes out.
  const bool rt_pipelined = barrier_.pipeline() == Pipeline::kRealtime;
  r.late = c.tick + (rt_pipelined ? 1 : 0) < barrier_.published();
  r.wake = barrier_.answer(id, c.tick, view(id));
  return r;
}

AgentRegistry::Expiry AgentRegistry::expire(double now, double agent_timeout_s) {
  Expiry e;
  double newest = -1e9;
  for (const auto& s : slots_)
    if (s.live) newest = std::max(newest, s.last_heard_wall_s);
  if (newest <= -1e9) return e;  // no live agent
  const bool was_silent = silence_.silent();
  const double timeout = silence_.limit(now, newest, agent_timeout_s);
  e.limit_s = timeout;
  e.newest_silence_s = now - newest;
  e.silence_began = silence_.silent() && !was_silent;
  // A live agent's silence as this check counts it (SwarmSilence).
  auto silence = [&](const AgentSlot& s) {
    return now - silence_.silent_since(s.last_heard_wall_s);
  };
  double longest = 0;
  for (const auto& s : slots_)
    if (s.live && silence(s) > timeout) {
      ++e.past_limit;
      longest = std::max(longest, silence(s));
    }
  if (!declare_lost_now(e.past_limit, longest, timeout)) {
    e.holding_began = !holding_lost_;
    holding_lost_ = true;
    return e;
  }
  holding_lost_ = false;
  for (int i = 0; i < size(); ++i) {
    AgentSlot& s = slots_[i];
    if (s.live && silence(s) > timeout) {
      s.live = false;
      s.owner = 0;
      barrier_.lose(i);
      e.lost.emplace_back(i, now - s.last_heard_wall_s);
    }
  }
  return e;
}

bool AgentRegistry::idle() const {
  for (const auto& s : slots_)
    if (s.live && s.busy) return false;
  return true;
}

}  // namespace ddswarm::sim
