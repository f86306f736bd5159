#pragma once
// How a process joins the swarm's DDS domain.
//
// The default reaches nothing but this machine: shared memory plus UDPv4
// bound to 127.0.0.1. Other hosts are reached only when the user names an
// interface, a list of peers, or a discovery server (docs/networking.md).
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "common/config_fields.hpp"

namespace CLI {
class App;
}

namespace ddswarm {

class YamlSection;

enum class Discovery {
  kLocalhost,        ///< default: SHM + UDP on 127.0.0.1 only
  kInterface,        ///< opt-in: multicast discovery on one named interface address
  kPeers,            ///< opt-in: unicast discovery to a static list of peer addresses
  kDiscoveryServer,  ///< opt-in: Fast DDS discovery server at ip:port
};

/// The last DDS domain whose RTPS ports fit in 16 bits.
constexpr int kMaxDomainId = 232;

/// The first of the 250 RTPS ports of domain_id (the default port mapping,
/// 7400 + 250*domain): every participant's ports in that domain lie above it.
constexpr int rtps_port_base(int domain_id) { return 7400 + 250 * domain_id; }

/// The RTPS metatraffic unicast port of a participant (the default port
/// mapping: 7400 + 250*domain + 10 + 2*id); its user-data port is one above.
int rtps_unicast_port(int domain_id, int participant_id);

/// The largest RTPS participant id whose ports fit in domain_id (29062 at
/// domain 0, 62 at domain 232). Fast DDS's automatic ids try only ~100.
int max_participant_id(int domain_id);
/// The participant ids, best first, of a participant that meets no agent
/// (DdsConfig::meets_agents): the domain's highest ids, above every agent's
/// (kAgentParticipantIdBase + drone, at most kMaxDrones drones), whose ports
/// (65470 and up) lie above the kernel's ephemeral range; kAboveAgentsIds of
/// them, for that many such participants at once. Empty when the domain's
/// port range has no room above the agents'.
std::vector<int> participant_ids_above_agents(int domain_id);
inline constexpr int kAboveAgentsIds = 32;

/// The kernel's ephemeral port range (/proc/sys/net/ipv4/ip_local_port_range):
/// any process's outgoing socket may hold a port inside it. Empty ({0, -1})
/// when it cannot be read.
struct PortRange {
  int lo = 0, hi = -1;
  bool contains(int port) const { return port >= lo && port <= hi; }
};
PortRange ephemeral_port_range();

/// Participant ids below this are kept for the server and tools, which take
/// automatic ids from 0 up; an agent's is this plus its drone id where one is
/// given: the launcher's for large swarms, and a secure agent's own
/// (DdsConfig::announce_to_tools_only).
constexpr int kAgentParticipantIdBase = 32;

/// The participants' lease (dds.lease_duration_s) in a swarm for which
/// ddswarm-launch starts a discovery server, unless its scenario names one,
/// and in bench/dds_floor's discovery-server runs. At the default 3 s, about
/// 1 launch in 10 of 128 agent processes loses the server for good
/// ("Matching unexisting participant from writer <server>"); at 20 s, none
/// in 16 does. A crashed process stays matched in DDS that much longer; ddswarm's
/// own timeouts (sim.agent_timeout_s, agent.server_timeout_s) do not depend
/// on it.
constexpr double kDiscoveryServerLeaseS = 20.0;

/// The lease of every participant under DDS Security on one host, unless the
/// scenario names dds.lease_duration_s (secure_lease). A secure bring-up keeps
/// both cores busy with handshakes: at 3 s, 64-agent launches lost agents'
/// leases, made 0-46 agents join again, and in 1 of 5 hung the server in a
/// Fast DDS 2.9 deadlock (a goodbye and a lapsed lease removed at once,
/// docs/security.md); at 20 s, 5 of 5 came up in 17-20 s, none joining again.
constexpr double kSecureLeaseS = 20.0;

/// The least lease a one-shot ground-station command announces (every
/// ddswarm-gs subcommand but the console, and each experiment run's ground
/// station; see one_shot). Each peer checks a participant's
/// lease on a timer that first fires one announced lease after discovering
/// it. In Debian's Fast DDS 2.9.1, a participant that says goodbye just as
/// that timer fires aborts the peer (PDP.cpp:1140, "GUID_t::unknown() !=
/// remote_participant->m_guid"): 90 `status` processes of about 3 s each,
/// against a 3 s lease, can abort 4 agents of 32. A command that leaves
/// before its lease has passed is never checked, so never races.
constexpr double kOneShotLeaseS = 20.0;

/// The UDP sockets' send and receive buffers every participant asks for:
/// room for a whole swarm's state, many ticks of it while a reader is busy.
/// Linux gives at most net.core.rmem_max (212,992 bytes by default), and
/// says nothing; the recorder warns when it is less (docs/recording.md).
constexpr std::uint32_t kUdpSocketBufferBytes = 2u << 20;

/// The shared-memory transport's segment of every process but an agent: its
/// outbox, where each sample it sends by that transport waits until every
/// local reader has taken it. The server's whole-swarm state, which a
/// recorder reads by the transport, is a few hundred KB at 1,024 drones.
constexpr std::uint32_t kShmSegmentBytes = 4u << 20;

/// An agent process's segment: 256 KiB, plus 16 KiB for each drone it flies,
/// at most kShmSegmentBytes. A drone's agent sends about 300 bytes a tick
/// (its command and beacon) and a heartbeat 4 times a second: 256 KiB holds
/// some 800 ticks of one drone's samples, and each drone's 16 KiB another 50,
/// so an agent host of 240 drones or more keeps the whole 4 MiB. Fast DDS
/// fills the segment as it makes it, so every byte stays resident: at 4 MiB,
/// 128 agent processes held 538 MB of /dev/shm, most of it never written
/// (docs/performance.md).
std::uint32_t agent_shm_segment_bytes(std::size_t drones);

/// Messages the shared-memory transport's port of every process but an agent
/// holds: its inbox, where each sample another process sends it by that
/// transport waits for the process's receive thread. Fast DDS 2.9 also lets a
/// process's outbox (its segment) hold only as many samples in flight as its
/// own port holds. Past either, samples are dropped, reliable or not, and
/// Fast DDS says nothing. Fast DDS's default is 512. 512 drones in 2 agent hosts
/// send the server 512 commands in a few milliseconds each tick: with 512 on
/// every side the server lost 0.07-0.20 % of them in every run, and none with
/// 4,096 or more (docs/performance.md). A message takes 25 bytes: 8,192 make
/// a 206 KB port, two per participant, and the outbox's table of as many
/// buffers adds 384 KiB to the segment.
constexpr std::uint32_t kShmPortQueue = 8192;

/// An agent process's port, and so the samples its outbox holds in flight:
/// 16 per drone it flies, at least Fast DDS's 512, at most kShmPortQueue.
/// A drone's agent sends one command a tick (and a beacon with comm beacons):
/// an agent host of 256 drones sends 256 at once, and keeps 4,096.
std::uint32_t agent_shm_port_queue(std::size_t drones);

/// dds.shm_health_check_s's default (see there).
constexpr double kShmHealthCheckS = 10.0;

struct DdsConfig {
  int domain_id = 0;
  Discovery discovery = Discovery::kLocalhost;
  std::string interface_ip;
  std::vector<std::string> peers;
  std::string discovery_server;
  bool shared_memory = true;
  /// false
  /// keeps data-sharing delivery (the swarm state) and sends every other
  /// sample (velocity commands, statuses, missions) over UDP on 127.0.0.1;
  /// 128 real-time agents then missed fewer commands (docs/performance.md).
  bool shm_transport = true;
  /// Bytes of the shared-memory transport's segment (this process's outbox);
  /// set by the binary for what it is, not read from YAML.
  std::uint32_t shm_segment_bytes = kShmSegmentBytes;
  /// Messages the shared-memory transport's port holds (this process's
  /// inbox); set by the binary for what it is, not read from YAML.
  std::uint32_t shm_port_queue = kShmPortQueue;
  /// Set explicitly past ~100 participants per host, at most
  /// max_participant_id(domain_id): the RTPS ports must fit.
  int participant_id = -1;
  double lease_duration_s = 3.0;
  /// The scenario names dds.lease_duration_s (set by load; secure_lease keeps it).
  bool lease_named = false;
  /// Fast DDS's healthy_check_timeout (1 s by default there). Fast DDS 2.9
  /// makes ports anew with races that can leave a live process listening on
  /// a port no sender reaches any more (docs/dds.md), so ddswarm keeps stalls
  /// shorter than this (a starved CI machine, a server stopped 8 s) off that
  /// path. The price: a process killed while it waited is found dead this
  /// much later, and the first process to open its port meanwhile waits up
  /// to this long.
  double shm_health_check_s = kShmHealthCheckS;
  /// s between this participant's announcements, < lease; 0: a third of the
  /// lease. Set by the binary (one_shot), not read from YAML.
  double announcement_period_s = 0.0;
  /// Localhost discovery without shared memory (so under DDS Security): send
  /// this participant's announcements only to the participant ids below
  /// kAgentParticipantIdBase, where the server and tools are, instead of to
  /// every id. Agents set it, so they never discover, and so never
  /// authenticate with, one another; tools, which announce to every id, still
  /// find them. At 24 secure drones the agents' handshakes and key exchanges
  /// with each other would keep the swarm from ever coming up (docs/security.md).
  /// Set by the binary, not read from YAML.
  bool announce_to_tools_only = false;
  /// false: never meet an agent (localhost discovery without shared memory,
  /// so under DDS Security): announce to the server's and tools' ids only, as
  /// agents do, from a participant id no agent announces to or takes (the top
  /// of the domain's port range, above every agent's: participant_id_above_agents).
  /// Ground stations set it under --secure: each one-shot command would
  /// otherwise authenticate with every agent, N handshakes that at 64 drones
  /// flood the server's and agents' discovery ports (docs/security.md). What
  /// it knows of agents then comes from the server. Set by the binary, not
  /// read from YAML.
  bool meets_agents = true;
  std::string profiles_file = std::string(DDSWARM_CONFIG_DIR) + "/dds_profiles.xml";
  /// A newer sample supersedes a lost one. Writers keep their profile (reliable), so any reliable
  /// reader (recorder, ground station, web view, a process with false) still
  /// gets every sample, and processes need not agree. Lockstep reads both
  /// streams reliably whatever this says: a tick waits for every state and
  /// command. Tools ignore it.
  bool best_effort_streams = true;
  /// --secure: a directory made by scripts/make-certs; empty = DDS Security off
  /// (docs/security.md). With it, the participant authenticates (PKI-DH), is
  /// access controlled (signed governance and permissions) and encrypts (AES-GCM).
  std::string security_dir;
  /// --security-role: which identity in security_dir to use (server, gs,
  /// recorder, viewer, agent-K); every binary defaults it to what it is.
  std::string security_role;

  /// The fields read from YAML, once (common/config_fields.hpp); the others
  /// are set by the binary or its command line.
  template <class Self, class V>
  static void fields(Self& c, V& v) {
    static const Choices<Discovery> kDiscovery{{"localhost", Discovery::kLocalhost},
                                               {"interface", Discovery::kInterface},
                                               {"peers", Discovery::kPeers},
                                               {"discovery_server", Discovery::kDiscoveryServer}};
    v.field("domain_id", c.domain_id, {"", in(0, kMaxDomainId), "DDS domain"});
    v.choice("discovery", c.discovery, kDiscovery, {"", any(), "how participants find each other"});
    v.field("interface_ip", c.interface_ip,
            {"", any(), "interface, peers: this host's address, e.g. 10.10.0.2"});
    v.field("peers", c.peers, {"", any(), "peers: the peers' addresses, ip or ip:port"});
    v.field("discovery_server", c.discovery_server,
            {"", any(), "discovery_server: ip:port (port 11811 if omitted)"});
    v.field("shared_memory", c.shared_memory,
            {"", any(), "the shared-memory transport and data-sharing (same host)"});
    v.field("shm_transport", c.shm_transport,
            {"", any(), "with shared_memory: Fast DDS's shared-memory transport too"});
    v.field("participant_id", c.participant_id, {"", any(), "RTPS participant id; -1 = automatic"});
    v.field("lease_duration_s", c.lease_duration_s,
            {"s", in(1, 300), "a silent participant is dropped after this"});
    v.field("shm_health_check_s", c.shm_health_check_s,
            {"s", in(0.1, 60),
             "how long a process may stall on a shared-memory port before it is made anew"});
    v.field("profiles_file", c.profiles_file, {"", any(), "the QoS profiles XML"});
    v.field("best_effort_streams", c.best_effort_streams,
            {"", any(), "the swarm's readers of the per-tick streams read them best-effort"});
  }

  void validate() const;  ///< throws FieldError("dds.…")
  bool secure() const { return !security_dir.empty(); }
  /// The files security_dir must hold for security_role, in order: identity
  /// CA, permissions CA, governance, permissions, certificate, private key.
  std::vector<std::string> security_files() const;
};

/// A one-shot command's config: a lease of at least kOneShotLeaseS, and the
/// announcements as often as the configured lease would have them (at a 20 s
/// lease, every 6.7 s, a Table 1 run waited 6.4 s to find its swarm).
DdsConfig one_shot(DdsConfig c);

/// Sets c.security_role to role unless the user chose one (--security-role).
void default_security_role(DdsConfig& c, const std::string& role);

/// The partition a drone's velocity commands travel in under DDS Security
/// (only agent-K may publish in drone/K; see docs/security.md).
std::string drone_partition(int drone_id);

void load(YamlSection s, DdsConfig& c);

/// Adds --domain, --dds-interface, --dds-peers, --discovery-server, --dds-profiles,
/// --secure, --security-role to a CLI11 app; their values override the YAML's after parsing.
void add_dds_options(CLI::App& app, DdsConfig& c);

}  // namespace ddswarm

namespace ddswarm {
/// Copies into target the DDS options the user actually gave on the command
/// line (cli was bound with add_dds_options), so flags override the YAML.
void merge_cli(DdsConfig& target, const DdsConfig& cli, const CLI::App& app);
/// Under DDS Security with localhost discovery, kSecureLeaseS unless the
/// scenario names a lease. merge_cli applies it; so must whatever else sets
/// security_dir.
void secure_lease(DdsConfig& c);
}  // namespace ddswarm
