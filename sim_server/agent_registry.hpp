#pragma once
// The server's record of each drone's agent: who flies it (ownership of the
// drone id, impostors refused), when it was last heard (liveness), and its
// last accepted command. Pure: no DDS, no clock of its own (wall times come
// in, in s), no I/O; it reports what the server logs. The server calls it
// with its mutex held.
#include <cstdint>
#include <utility>
#include <vector>

#include "common/mission.hpp"
#include "sim_server/agent_liveness.hpp"
#include "sim_server/command_gate.hpp"
#include "sim_server/tick_barrier.hpp"

namespace ddswarm::sim {

/// What the server knows about one drone's agent and its last command.
struct AgentSlot {
  VelocitySetpoint setpoint;  ///< last accepted command (world frame)
  bool has_command = false;
  std::uint64_t command_tick = 0;  ///< the tick it answered
  bool busy = false;               ///< lockstep: its agent needs the clock to run
  Phase phase = Phase::kIdle;
  std::uint64_t owner = 0;  ///< agent instance flying this drone, 0 = none
  bool live = false;
  double last_heard_wall_s = -1e9;
  std::uint32_t mission_seq =
      0;  ///< last mission command its agent accepted (relayed in SimStatus)
  std::uint64_t mission_issuer = 0;  ///< and its issuer
};

/// An accepted command's contents, as the registry keeps them.
struct CommandRecord {
  VelocitySetpoint setpoint;
  std::uint64_t tick = 0;
  Phase phase = Phase::kIdle;
  std::uint32_t mission_seq = 0;
  std::uint64_t mission_issuer = 0;
  bool busy = false;
};

class AgentRegistry {
 public:
  /// lockstep: every answer is for the published tick (GateContext).
  AgentRegistry(int drones, bool lockstep, Pipeline pipeline);

  int size() const { return static_cast<int>(slots_.size()); }
  const AgentSlot& operator[](int i) const { return slots_[i]; }
  CommandView view(int i) const;
  TickBarrier& barrier() { return barrier_; }
  const TickBarrier& barrier() const { return barrier_; }

  /// Tick `tick` goes out: the barrier owes it an answer from every live agent.
  void publish(std::uint64_t tick) {
    barrier_.publish(tick, [this](int i) { return view(i); });
  }

  enum class Heard {
    kHeard,      ///< its live agent
    kOnline,     ///< a new agent: now live
    kUnknownId,  ///< no such drone in this scenario
    kImpostor,   ///< another instance already flies this drone
  };
  /// A heartbeat from instance for drone id at now_wall_s.
  Heard heartbeat(int id, std::uint64_t instance, double now_wall_s);

  /// The command gate's verdict on c, from what the registry knows of its drone.
  Verdict check(const CommandFacts& c, double max_speed_mps) const;

  struct Recorded {
    bool online = false;      ///< this command made its agent live
    bool status_due = false;  ///< live, mission or phase changed: SimStatus goes out now
    bool late = false;        ///< for a step already taken (counted in commands_late)
    bool wake = false;        ///< the barrier's last owed answer (TickBarrier::answer)
  };
  /// Keeps an accepted command (check said kAccept) from instance for drone id.
  Recorded record(int id, std::uint64_t instance, const CommandRecord& c, double now_wall_s);

  /// What expire found, in the order the server reports it.
  struct Expiry {
    bool silence_began = false;   ///< no live agent heard for a while: limit_s lengthened
    double newest_silence_s = 0;  ///< s since any live agent was heard
    double limit_s = 0;           ///< the silence limit that applied
    bool holding_began = false;   ///< several past the limit at once: held (declare_lost_now)
    int past_limit = 0;
    std::vector<std::pair<int, double>> lost;  ///< (drone, s since heard) declared lost now
  };
  /// Declares lost the live agents silent past their limit at now_wall_s
  /// (agent_liveness.hpp): they owe no answers and their drones enter failsafe.
  Expiry expire(double now_wall_s, double agent_timeout_s);

  /// Every live agent is idle (none needs the clock to run).
  bool idle() const;

 private:
  bool adopt(AgentSlot& s, int id, std::uint64_t instance, double now_wall_s);

  bool lockstep_;
  std::vector<AgentSlot> slots_;
  TickBarrier barrier_;
  SwarmSilence silence_;
  bool holding_lost_ = false;
};

}  // namespace ddswarm::sim
