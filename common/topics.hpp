#pragma once
// The one place that names every topic, its type and its QoS profile.
#include "AgentStatusPubSubTypes.h"
#include "BeaconPubSubTypes.h"
#include "CollisionEventPubSubTypes.h"
#include "DistanceScanPubSubTypes.h"
#include "DroneStatePubSubTypes.h"
#include "MissionAckPubSubTypes.h"
#include "MissionCommandPubSubTypes.h"
#include "ScenePubSubTypes.h"
#include "SimStatusPubSubTypes.h"
#include "SwarmStatePubSubTypes.h"
#include "TaskStatusPubSubTypes.h"
#include "VelocityCommandPubSubTypes.h"

#include <fastcdr/exceptions/Exception.h>

#include <atomic>
#include <cstdint>

namespace ddswarm {

/// Samples refused on the wire in this process (undecodable CDR), every topic.
inline std::atomic<std::uint64_t>& malformed_samples() {
  static std::atomic<std::uint64_t> n{0};
  return n;
}

/// The generated type support, refusing a malformed sample instead of
/// throwing. Fast CDR throws BadParamException for, e.g., a bool byte other
/// than 0 or 1; the generated deserialize() catches only a truncated buffer,
/// so one such sample from any participant on the domain would escape into
/// Fast DDS's reader thread and terminate the process. This deserialize()
/// returns false instead (Fast DDS drops the sample) and malformed_samples()
/// counts it.
template <class Generated>
class SafePubSub : public Generated {
 public:
  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override {
    try {
      if (Generated::deserialize(payload, data)) return true;
    } catch (const eprosima::fastcdr::exception::Exception&) {
    }
    malformed_samples().fetch_add(1, std::memory_order_relaxed);
    return false;
  }
};

/// The swarm state, which every agent reads every tick, decodes inline
/// (decode_swarm_state in common/swarm_state_cdr.hpp), to the same sample.
template <>
bool SafePubSub<msg::SwarmStatePubSubType>::deserialize(
    eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data);

template <class T>
struct Topic;

#define DDSWARM_TOPIC(Type, topic_name, qos_profile)    \
  template <>                                           \
  struct Topic<msg::Type> {                             \
    using PubSub = SafePubSub<msg::Type##PubSubType>;   \
    static constexpr const char* name = topic_name;     \
    static constexpr const char* profile = qos_profile; \
  }

DDSWARM_TOPIC(SwarmState, "ddswarm/swarm_state", "state");
DDSWARM_TOPIC(DroneState, "ddswarm/drone_state", "state_keyed");
DDSWARM_TOPIC(DistanceScan, "ddswarm/scan", "state_keyed");
DDSWARM_TOPIC(Scene, "ddswarm/scene", "latched");
DDSWARM_TOPIC(SimStatus, "ddswarm/status", "status");
DDSWARM_TOPIC(CollisionEvent, "ddswarm/collision", "events");
DDSWARM_TOPIC(TaskStatus, "ddswarm/task", "latched");
DDSWARM_TOPIC(VelocityCommand, "ddswarm/velocity_cmd", "command");
DDSWARM_TOPIC(AgentStatus, "ddswarm/agent_status", "heartbeat");
DDSWARM_TOPIC(MissionCommand, "ddswarm/mission", "mission");
DDSWARM_TOPIC(MissionAck, "ddswarm/mission_ack", "ack");
DDSWARM_TOPIC(Beacon, "ddswarm/beacon", "state_keyed");

#undef DDSWARM_TOPIC

/// Topics whose writers publish in their drone's partition (drone_partition())
/// under DDS Security, so permissions can say whose drone a writer may
/// address; readers then subscribe to "drone/*" (docs/security.md).
template <class T>
inline constexpr bool kPerDronePartition = false;
template <>
inline constexpr bool kPerDronePartition<msg::VelocityCommand> = true;

/// The participant name the simulation server joins DDS under (it shows in
/// tools; agents look for it by name: Participant::peers_named).
inline constexpr const char* kServerParticipantName = "ddswarm-sim";

/// What ddswarm-record prints once its swarm-state reader has matched a
/// server's writer. ddswarm-launch and the experiment runner start the agents
/// only then (ChildSpec::ready_line): a lockstep task flies in a second or two,
/// and a recorder that matched later missed the flight's start.
inline constexpr const char* kRecorderMatchedServer =
    "ddswarm-record: matched the server's swarm state";

/// The per-tick streams, state out and commands back: a newer sample
/// supersedes a lost one, so in real time the swarm's own readers may read
/// them best-effort (dds.best_effort_streams, Delivery::kLatest).
template <class T>
inline constexpr bool kPerTickStream = false;
template <>
inline constexpr bool kPerTickStream<msg::SwarmState> = true;
template <>
inline constexpr bool kPerTickStream<msg::VelocityCommand> = true;

/// Calls f.template operator()<T>() for every message type that has a topic
/// (for tools that handle all of them: recorder, replay).
template <class F>
void for_each_topic_type(F&& f) {
  f.template operator()<msg::SwarmState>();
  f.template operator()<msg::DroneState>();
  f.template operator()<msg::DistanceScan>();
  f.template operator()<msg::Scene>();
  f.template operator()<msg::SimStatus>();
  f.template operator()<msg::CollisionEvent>();
  f.template operator()<msg::TaskStatus>();
  f.template operator()<msg::VelocityCommand>();
  f.template operator()<msg::AgentStatus>();
  f.template operator()<msg::MissionCommand>();
  f.template operator()<msg::MissionAck>();
  f.template operator()<msg::Beacon>();
}

}  // namespace ddswarm
