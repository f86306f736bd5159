#pragma once
// Starts and supervises ddswarm processes: prefixes and collects their logs,
// says which one died and why, and tears everything down cleanly.
#include <sys/types.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <cstdio>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "common/dds_config.hpp"
#include "common/id_ranges.hpp"

namespace ddswarm::gs {

struct ChildSpec {
  std::string name;               ///< log prefix, e.g. "sim", "agent 3"
  std::vector<std::string> argv;  ///< argv[0] is the executable path
  /// A line the child prints once it is ready (Launcher::wait_ready); "": none.
  std::string ready_line = {};
};

struct ChildExit {
  std::string name;
  pid_t pid = 0;
  int exit_code = -1;  ///< when it exited
  int signal = 0;      ///< when a signal killed it
  std::string describe()
      const;  ///< "agent 3 (pid 1234) exited with code 1" / "was killed by SIGKILL"
};

/// --on-death restart: whether an agent's end is one that starting it again
/// can mend. A signal (a crash such as Fast DDS 2.9.1's assertion in
/// docs/faults.md, an OOM kill, a SIGKILL) or an unexpected exit code is;
/// exit 0 (its --duration), 2 (its configuration) and 3 (another agent flies
/// its drone) are not, since they would recur. The launcher's own SIGTERM
/// never reaches this: it reaps nothing while stopping.
bool worth_restarting(const ChildExit& e);
/// How many times --on-death restart starts one agent again.
constexpr int kMaxRestarts = 3;

/// How long ddswarm-launch and the experiment runner wait for their recorder
/// to hear the server (kRecorderMatchedServer) before they start the agents.
constexpr double kRecorderWaitS = 30.0;

/// --on-death: what the launcher does when one of its processes ends.
/// kStop: stop everything. kKeep: report it and keep flying. kRestart: start
/// a restartable process (an agent) again when worth_restarting says it can
/// mend, up to kMaxRestarts times each; any other end stops everything.
/// Whatever the policy, the launcher's own discovery server is started again
/// on a crash (DeathPolicy::always_restart): it flies no drone, and Fast DDS
/// 2.9.1's fast-discovery-server can abort on an assertion (docs/faults.md).
enum class OnDeath { kStop, kKeep, kRestart };
/// "stop", "keep" or "restart"; throws std::invalid_argument naming the value.
OnDeath parse_on_death(const std::string& text);

/// The bookkeeping of --on-death, with no processes in it: the launcher
/// reports each child that ended, and is told what to start again and
/// whether to stop.
class DeathPolicy {
 public:
  explicit DeathPolicy(OnDeath policy) : policy_(policy) {}
  /// A process that kRestart may start again (the launcher's agents).
  void restartable(const ChildSpec& spec) { restartable_[spec.name] = spec; }
  /// A process started again whatever the policy, when worth_restarting says
  /// it can mend, up to kMaxRestarts times (the launcher's discovery server).
  void always_restart(const ChildSpec& spec) { always_[spec.name] = spec; }
  /// A child ended: the spec to start again, or nothing (it died).
  std::optional<ChildSpec> ended(const ChildExit& e);
  /// Some child ended and was not started again.
  bool died() const { return died_; }
  /// The launcher should stop everything: a death, unless kKeep.
  bool stop() const { return died_ && policy_ != OnDeath::kKeep; }
  /// How many times the child of that name was started again.
  int restarts(const std::string& name) const;

 private:
  OnDeath policy_;
  std::map<std::string, ChildSpec> restartable_;
  std::map<std::string, ChildSpec> always_;
  std::map<std::string, int> restarts_;
  bool died_ = false;
};

/// Runs spec to its end and returns how it ended; output gets its stdout and
/// stderr together. For quick checks (`ddswarm-sim --check`): no timeout, no
/// supervision. Throws std::runtime_error when it cannot start.
ChildExit run_to_end(const ChildSpec& spec, std::string& output);

class Launcher {
 public:
  /// log_dir: when set, each child's output goes to <log_dir>/<name>.log
  /// instead of this process's stdout (prefixed there otherwise).
  explicit Launcher(std::string log_dir = "");
  ~Launcher();  ///< stops every child still running
  Launcher(const Launcher&) = delete;
  Launcher& operator=(const Launcher&) = delete;

  /// Forks and execs; throws std::runtime_error naming the program on failure.
  /// A name started before (a restart) appends to its log file.
  pid_t start(const ChildSpec& spec);
  /// Children that ended since the last call (never blocks).
  std::vector<ChildExit> reap();
  int running() const;
  /// SIGTERM to every child, SIGKILL after grace_s; waits for all of them.
  /// Returns the exits it collected.
  std::vector<ChildExit> stop_all(double grace_s = 3.0);
  /// Sends sig to one child by name (tests, fault injection).
  bool signal(const std::string& name, int sig);
  /// Reads child `ds_name`'s output as a Fast DDS discovery server's: when it
  /// drops a participant's endpoints for good (dropped_participant_prefix;
  /// for the server also unmatched_participant_prefix), the agent or server
  /// child whose process that participant is gets SIGUSR1 (join again), once
  /// per participant, and the launcher says so on stderr.
  void rejoin_dropped_participants(const std::string& ds_name);
  /// Waits until child `name` has printed a line holding its spec's
  /// ready_line, it ended, timeout_s passed or a stop was requested; true
  /// when it printed it.
  bool wait_ready(const std::string& name, double timeout_s);

  /// Directory of the running executable (where the sibling binaries live).
  static std::string self_dir();

 private:
  struct Child {
    std::string name;
    pid_t pid;
    int out_fd;
    std::string partial;
    FILE* log = nullptr;
    std::string ready_line;  ///< ChildSpec::ready_line
    bool ready = false;      ///< it printed ready_line
  };
  void pump();
  void emit(Child& c, const char* data, std::size_t n, bool flush);
  /// mu_ held. server_only: act only when the participant is the server's.
  void on_dropped(const std::array<std::uint8_t, 12>& prefix, bool server_only);

  std::string drop_watch_;                               ///< rejoin_dropped_participants
  std::set<std::array<std::uint8_t, 12>> dropped_seen_;  ///< participants already acted on

  std::string log_dir_;
  std::set<std::string> logs_opened_;  ///< log files of this launcher's children so far
  mutable std::mutex mu_;
  std::map<pid_t, std::unique_ptr<Child>> live_;
  std::vector<std::unique_ptr<Child>> closed_;
  std::atomic<bool> quit_{false};
  int wake_[2] = {-1, -1};
  std::thread pump_;
};

using ddswarm::parse_id_ranges;  // common/id_ranges.hpp

/// The launcher's --discovery-server: whether it runs a Fast DDS discovery
/// server for the swarm, or points every child at one elsewhere.
struct DiscoveryServerChoice {
  enum class Kind {
    kAuto,      ///< start a local server when the swarm is large enough for it to help
    kOn,        ///< always start a local server
    kOff,       ///< never: simple discovery (or what the scenario's dds section says)
    kExternal,  ///< use the server at `address` (ip:port), started by someone else
  };
  Kind kind = Kind::kAuto;
  std::string address;  ///< kExternal: "ip:port"
};

/// Parses auto | on | off | IP:PORT; throws std::invalid_argument naming the text.
DiscoveryServerChoice parse_discovery_server(const std::string& text);

/// With auto, swarms of more than this many drones get a local discovery
/// server: simple discovery is O(N^2) and above ~32 processes the server
/// discovers faster and idles cheaper (docs/performance.md, bench/dds_floor).
constexpr int kAutoDiscoveryServerAbove = 32;

/// Fast DDS 2.9 gives a participant with an automatic id the first free port
/// pair among 100 (ids 0-99), so past ~100 participants per host and domain the
/// rest are unreachable, discovery server or not (bench/dds_floor). Large
/// swarms' agents therefore get explicit ids, from kFirstAgentParticipantId
/// up, leaving ids below it for the server and tools (automatic). Automatic
/// ids search upwards from 0 for a free port pair, so every tool that joins
/// (ground stations, recorder, probes, web bridge) needs a free id below the
/// agents: with 4 free, the fifth tool of a 128-process swarm never found the
/// server. 32 leaves room for them all.
constexpr int kExplicitParticipantIdsAbove = 90;
constexpr int kFirstAgentParticipantId = kAgentParticipantIdBase;  // common/dds_config.hpp
constexpr int kMaxParticipantId = 1100;  ///< 1024 drones and then some; dds.participant_id also
                                         ///< bounds it by domain (common/dds_config)

/// The RTPS participant id the launcher gives drone_id's agent in a swarm of
/// `drones`, or -1 for Fast DDS's automatic one.
int agent_participant_id(int drones, int drone_id);

/// Agent hosts: the ids split into at most `hosts` contiguous shares as equal
/// as ceil(ids / hosts) makes them, each the `--ids` argument of one
/// `ddswarm-agent` ("0,1,2"). Fewer shares when there are fewer ids than hosts.
std::vector<std::string> agent_host_shares(const std::vector<int>& ids, int hosts);

/// The command that starts one agent process: drone `ids` alone (`--id`), or
/// a share of agent_host_shares as an agent host (`--ids`), reading scenario.
/// started_with_server: the same tool starts the server and every agent of
/// the swarm, so no other agent flies these drones and the agent skips its
/// duplicate probe (`--duplicate-probe 0`). N probe readers each matching N
/// status writers keep a 128-process swarm from coming up at all
/// (docs/performance.md, "Bringing up 128 processes"); agents launched apart
/// from their server keep it.
std::vector<std::string> agent_command(const std::string& bin, const std::string& ids, bool host,
                                       const std::string& scenario, bool started_with_server);

/// The RTPS unicast ports (metatraffic and user, 7400 + 250*domain + 10/11 +
/// 2*id) of explicit participant ids [first_id, last_id] that fall inside the
/// kernel's ephemeral port range (ephemeral_port_range(), common/dds_config).
/// Any process's outgoing socket may hold such a port, and the participant that
/// needs it then never binds it and is never discovered (2 of 128 agents in
/// domain 120+, docs/performance.md). Returns a one-line warning naming the
/// largest domain that keeps clear of the range, or "" when clear.
std::string ephemeral_port_warning(int domain, int first_id, int last_id, PortRange ephemeral);

/// True when the launcher should start its own server. `starts_whole_swarm`:
/// it starts the server and every agent (a local server cannot serve a swarm
/// split across hosts); `localhost_discovery`: no other network was opted into.
bool wants_local_discovery_server(const DiscoveryServerChoice& c, int drones,
                                  bool starts_whole_swarm, bool localhost_discovery);

/// fast-discovery-server on 127.0.0.1:port only (config/discovery_server.xml
/// keeps its transports off every other interface). Throws std::runtime_error
/// when the program is not installed.
ChildSpec discovery_server_spec(int port);

/// A UDP port on 127.0.0.1 that was free a moment ago.
int free_udp_port();

/// The GUID prefix in a line of fast-discovery-server's log that says it
/// dropped a participant's endpoint for good ("Writer <prefix>|<entity> has no
/// associated participant. Skipping": Fast DDS 2.9 processed the endpoint
/// before its participant, and never matches it afterwards; docs/performance.md),
/// or nothing. Colour codes are ignored.
std::optional<std::array<std::uint8_t, 12>> dropped_participant_prefix(const std::string& line);

/// The GUID prefix in a fast-discovery-server log line "Matching unexisting
/// participant from writer|reader <prefix>|<entity>": it matches endpoints
/// of a participant it has lost (once in eight 128-process launches, the
/// server's, and no agent ever got the scene), or nothing. The participant
/// may also be one that has just left, so the launcher acts on it only for
/// the server, which never leaves by itself.
std::optional<std::array<std::uint8_t, 12>> unmatched_participant_prefix(const std::string& line);

/// The low 16 bits of the process id in a Fast DDS 2.9 GUID prefix (bytes 4-5,
/// little-endian): which process a participant lives in.
int prefix_pid16(const std::array<std::uint8_t, 12>& prefix);

}  // namespace ddswarm::gs
