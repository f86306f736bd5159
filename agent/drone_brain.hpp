#pragma once
// One drone's brain, pure: what the drone receives in a tick in, what it
// sends out. Per tick, DroneBrain::tick maps a SwarmTick (one swarm-state
// sample, converted once for every brain of a process) to the drone's
// velocity command, its mission acks and its beacon, keeping the drone's
// mission, peer knowledge, law and answers between ticks. No DDS, no clock,
// no log: the agent application converts, writes and logs what it returns.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "agent/agent_config.hpp"
#include "agent/comm_config.hpp"
#include "agent/comm_model.hpp"
#include "agent/mission_fsm.hpp"
#include "agent/peer_source.hpp"
#include "agent/swarm_law.hpp"
#include "common/mission.hpp"
#include "common/scene.hpp"
#include "ddswarm/law.hpp"

namespace ddswarm::agent {

/// One drone's row of a swarm-state sample.
struct DroneRow {
  int id = -1;
  bool valid = false;       ///< position and velocity finite: the drone can be flown from it
  bool agent_live = false;  ///< the server hears a live agent for this drone
  Eigen::Vector3d p_world{0, 0, 0};  ///< m, ENU
  Eigen::Vector3d v_world{0, 0, 0};  ///< m/s, ENU
  Eigen::Quaterniond q_world_body = Eigen::Quaterniond::Identity();
  /// The drone's ray scan, as the sample holds it (the sample outlives the
  /// tick): one entry per ray in each span. A scan whose spans differ in
  /// length, or with a ray whose yaw or elevation is not finite, is refused
  /// whole and counted (rejected()); a ray with a non-finite range is no hit.
  std::span<const float> ray_range_m;
  std::span<const std::uint8_t> ray_hit;
  std::span<const float> ray_yaw_body_rad;
  std::span<const float> ray_elevation_body_rad;  ///< rad, up from the body x-y plane
};

/// A mission command in the server's ring of recent commands.
struct RelayedMission {
  MissionCommand command;
  std::uint64_t issuer_instance = 0;
  std::uint64_t apply_tick = 0;  ///< the tick the swarm applies it at
  std::string problem;           ///< why the sample's command is malformed; empty when sound
};

/// One swarm-state sample as every brain of a process reads it.
struct SwarmTick {
  std::uint64_t tick = 0;
  double sim_time_s = 0;
  std::vector<DroneRow> drones;  ///< the server's rows; row k flies drone k
  /// The swarm's members (live agent, not in failsafe, finite position), by id.
  std::vector<PeerObservation> roster;
  std::vector<RelayedMission> missions;  ///< the ring of recent commands, oldest first
  std::vector<PeerMessage> beacons;      ///< the beacons the server relays this tick

  /// Drone id's row, or nullptr when the sample has none for it.
  const DroneRow* row(int id) const {
    if (id < 0 || static_cast<std::size_t>(id) >= drones.size() || drones[id].id != id)
      return nullptr;
    return &drones[id];
  }
};

/// What the drone sends as its VelocityCommand.
struct DroneCommand {
  int drone_id = -1;
  std::uint64_t tick = 0;
  double sim_time_s = 0;
  Eigen::Vector3d velocity{0, 0, 0};  ///< m/s, world
  double yaw_rate_rad_s = 0;          ///< rad/s, the law's (the thesis law holds the heading)
  bool motors_on = false;
  Phase phase = Phase::kIdle;
  bool busy = false;
  std::uint32_t mission_seq = 0;     ///< the last mission command accepted
  std::uint64_t mission_issuer = 0;  ///< and its issuer instance
  std::uint64_t agent_instance = 0;
  /// The drone's beacon this tick (comm.source beacons, when one is due).
  std::optional<PeerMessage> beacon;
  Eigen::Vector3d beacon_velocity{0, 0, 0};  ///< m/s, the velocity the beacon reports
};

/// A line for the agent's log.
struct BrainNote {
  enum class Level { kInfo, kWarn, kError };
  Level level = Level::kInfo;
  std::string text;
};

struct AckOut {
  MissionAck ack;
  std::uint64_t issuer_instance = 0;  ///< the command's issuer, which the ack goes to
};

/// What one tick asks the application to send and log.
struct TickAnswer {
  enum class Kind {
    kNone,    ///< nothing to send: no mission yet, or no usable row for the drone
    kRepeat,  ///< a tick answered before: the same command again, nothing else
    kFresh,   ///< a new answer
  };
  Kind kind = Kind::kNone;
  DroneCommand command;
  std::vector<AckOut> acks;     ///< in the order the commands came
  bool publish_beacon = false;  ///< command.beacon is new: write it on the beacon topic too
  std::vector<BrainNote> notes;
};

class DroneBrain {
 public:
  /// Hover this long (s, sim) after a law faults, then land.
  static constexpr double kLawFaultHoverS = 2.0;

  /// agent and comm must outlive the brain; num_drones: scenario.drones.
  DroneBrain(int id, std::uint64_t instance, const AgentConfig& agent, const CommConfig& comm,
             int num_drones);
  ~DroneBrain();
  DroneBrain(const DroneBrain&) = delete;
  DroneBrain& operator=(const DroneBrain&) = delete;

  /// A scene starts the mission: the mission machine, the law (built from
  /// law_seed(seed, id)), the peer source. Returns what the log should say
  /// (a law that cannot be built faults the drone at once).
  std::vector<BrainNote> start(const SceneConfig& scene, double control_rate_hz,
                               std::uint64_t seed);
  /// A new server: the mission, the law and what was heard are forgotten
  /// until start() (law faults are kept).
  void reset();

  /// One tick: the missions of t's ring not yet handled (caught up with on
  /// the first tick after start, when their apply tick has passed), then the
  /// command. A tick answered before gets the same command again, so the
  /// mission machine and the law run once per tick.
  TickAnswer tick(const SwarmTick& t);

  int id() const { return id_; }
  std::uint64_t instance() const { return instance_; }
  bool started() const { return fsm_ != nullptr; }
  /// kFailsafe once the law faulted, else the mission's phase.
  Phase phase() const;
  double inter_distance_m() const;
  std::uint64_t rejected() const { return rejected_; }  ///< malformed rows, rays and commands
  std::uint64_t sent() const { return sent_; }          ///< fresh answers
  const LawConfig& law_config() const { return *law_cfg_; }
  const std::string& law_fault() const { return law_fault_; }  ///< empty while the law is sound
  std::uint64_t law_faults() const { return law_faults_; }
  /// The peer source, when the communication model delivers the peers.
  const ModelledPeerSource* modelled() const { return modelled_.get(); }

 private:
  void handle_missions(const SwarmTick& t, const Observation& obs, TickAnswer& a);
  void feed_peers(const SwarmTick& t, const DroneRow& me, bool new_tick, Eigen::Vector3d& own_p);
  void fault(const std::string& why, double t, TickAnswer& a);
  void fly_fault(LawInput& in, MissionOutput& out, const Observation& obs);
  law::Observation observe(const LawInput& in, const MissionOutput& out, const Observation& obs,
                           const SwarmTick& t);
  LawTerms command(LawInput& in, MissionOutput& out, const Observation& obs, const SwarmTick& t,
                   TickAnswer& a);

  const int id_;
  const std::uint64_t instance_;
  const AgentConfig& agent_;
  const CommConfig& comm_;
  const int num_drones_;
  const LawConfig* law_cfg_;
  // From the scene.
  double control_period_s_ = 0.02;
  double ground_z_m_ = 0;
  Eigen::Vector2d goal_xy_{0, 0};

  std::unique_ptr<MissionFsm> fsm_;
  TruthPeerSource truth_;
  std::unique_ptr<ModelledPeerSource> modelled_;  // when comm asks for more than exact truth
  PeerSource* peers_ = &truth_;
  std::uint64_t fed_tick_ = ~0ULL;  // the tick whose truth and beacons the peer source has taken
  // (issuer, seq) -> the apply tick it came with; oldest first for pruning.
  std::map<std::pair<std::uint64_t, std::uint32_t>, std::uint64_t> seen_missions_;
  std::deque<std::pair<std::uint64_t, std::uint32_t>> seen_order_;
  std::uint32_t last_mission_seq_ = 0;     // the last mission command accepted: its seq
  std::uint64_t last_mission_issuer_ = 0;  // and its issuer instance
  bool caught_up_ = false;  // the mission in force (the ring) was taken from the first tick
  std::uint64_t rejected_ = 0, sent_ = 0;
  std::vector<Eigen::Vector3d> ranged_;
  std::vector<float> ranges_, angles_, elevations_;
  std::vector<std::uint8_t> hits_;

  std::unique_ptr<law::SwarmLaw> law_;
  std::vector<law::Peer> law_peers_;
  std::vector<law::Ray> law_rays_;
  double yaw_rate_rad_s_ = 0;  // the law's, this tick
  std::string law_fault_;      // the first fault; empty while the law is sound
  std::uint64_t law_faults_ = 0;
  double law_fault_at_s_ = -1;  // sim time of the fault
  bool fault_landing_ = false;  // the fault's hover ended and the landing was ordered

  // The last answer. A tick that comes again (lockstep: the server published
  // it twice, a sample was lost) gets the same answer again.
  std::optional<DroneCommand> last_answer_;
};

}  // namespace ddswarm::agent
