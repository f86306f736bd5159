#include "sim_server/mission_relay.hpp"

#include "common/convert.hpp"
#include "common/mission.hpp"
#include "sim_server/mission_ring.hpp"

namespace ddswarm::sim {

MissionRelay::Intake MissionRelay::take(const msg::MissionCommand& m, std::string& problem) {
  problem = mission_problem(m);
  if (!problem.empty()) return Intake::kMalformed;
  // Addressed to a server that is gone (e.g. a ground station's
  // transient-local history meeting a restarted server): the mission it
  // belonged to ended with that world.
  if (m.server_instance() != 0 && m.server_instance() != instance_) return Intake::kStale;
  // A repeat (the ground station lost an ack, or re-sent its history to a
  // restarted server) is forwarded again: agents re-acknowledge it and do not re-apply it.
  const bool repeat = !seen_.insert({m.issuer_instance(), m.seq()}).second;
  pending_.push_back(m);
  return repeat ? Intake::kRepeat : Intake::kNew;
}

void MissionRelay::forward(msg::MissionCommand m, std::uint64_t tick) {
  m.apply_tick(tick);
  // One entry per command in the ring, or agents would see it alternate between apply ticks.
  std::erase_if(ring_, [&](const msg::MissionCommand& r) {
    return r.issuer_instance() == m.issuer_instance() && r.seq() == m.seq();
  });
  ring_.push_back(m);
  trim_recent(ring_, 8);
}

std::optional<msg::MissionCommand> MissionRelay::release(std::uint64_t tick) {
  while (!pending_.empty() &&
         released_.count({pending_.front().issuer_instance(), pending_.front().seq()})) {
    forward(pending_.front(), tick);
    pending_.pop_front();
  }
  if (pending_.empty()) return std::nullopt;
  msg::MissionCommand m = pending_.front();
  pending_.pop_front();
  forward(m, tick);
  released_.insert({m.issuer_instance(), m.seq()});
  if (static_cast<MissionType>(m.type()) == MissionType::kSetDistance) distance_m_ = m.value();
  return m;
}

}  // namespace ddswarm::sim
