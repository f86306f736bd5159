#pragma once
// What the server hears on DDS: agents' commands and heartbeats, mission
// commands, and other servers' scenes and statuses. The handlers run on Fast
// DDS threads and keep what they take in (agent registry and tick barrier,
// mission relay, rival arbiter, beacons, rejection counters) under one
// mutex, which the main loop holds to read it.
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <vector>

#include "AgentStatus.h"
#include "Beacon.h"
#include "MissionCommand.h"
#include "SimStatus.h"
#include "VelocityCommand.h"
#include "common/participant.hpp"
#include "sim_server/agent_registry.hpp"
#include "sim_server/mission_relay.hpp"
#include "sim_server/rival_arbiter.hpp"
#include "sim_server/sim_server.hpp"

namespace ddswarm::sim {

struct ServerInbox {
  /// cfg outlives the inbox; instance is this server's.
  ServerInbox(const ServerConfig& cfg, std::uint64_t instance, Pipeline pipeline);

  /// Makes dds deliver to the handlers below. Close dds before destroying the inbox.
  void subscribe(Participant& dds);

  /// Declares lost the agents silent past their limit (agent_liveness.hpp),
  /// and logs it. Call with mu held, at wall time now_wall_s.
  void expire_agents(double now_wall_s);

  /// What the main loop reads once per tick, with mu held: each drone's
  /// agent live and phase; and the beacons accepted commands carried, in
  /// drone order (the radio medium), moved into `beacons_out`.
  void take_tick(std::vector<char>& live, std::vector<Phase>& phase,
                 std::vector<msg::Beacon>& beacons_out);

  /// A rejoin request came (SIGUSR1): true when the server may leave DDS and
  /// start again as a new server, which it may only before any mission
  /// command came; logs either way. Takes mu.
  bool may_rejoin();

  // ---- handlers (Fast DDS threads) ----
  void on_command(const msg::VelocityCommand& c);
  void on_heartbeat(const msg::AgentStatus& a);
  void on_mission(const msg::MissionCommand& m);
  /// Another server on this domain (rival_arbiter.hpp): yield, or say once that it should.
  void on_rival_scene(std::uint64_t other, std::int64_t other_published_ns);
  void on_rival_status(const msg::SimStatus& s);

  const ServerConfig& cfg;
  const int n;
  const std::uint64_t instance;

  // Guarded by mu.
  std::mutex mu;
  std::condition_variable cv;  // an answer, agent or command the main loop waits for came in
  AgentRegistry agents;
  MissionRelay missions;
  RivalArbiter arbiter;
  std::vector<msg::Beacon> beacons;  // carried by accepted commands, forwarded next tick
  msg::SimStatus counters;           // rejected_* and commands_* live here
  double agent_d_int = 0;            // m, the largest D_int an agent reported
  // What a ground station waits for changed since the last SimStatus: an
  // agent came online or was lost, accepted a new mission command, or changed
  // phase. Set under mu; atomic so the per-tick check in publish_status needs
  // no lock.
  std::atomic<bool> status_due{false};
  // Another server's instance, when this one yields to it (set under mu, read
  // without it by the per-turn check).
  std::atomic<std::uint64_t> rival_instance{0};

 private:
  void yield_to(std::uint64_t other);  // call with mu held
};

}  // namespace ddswarm::sim
