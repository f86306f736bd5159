#include "common/participant.hpp"

#include "common/shm_clean.hpp"

#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/shared_mem/SharedMemTransportDescriptor.h>
#include <fastrtps/utils/IPLocator.h>
#include <fastrtps/xmlparser/XMLProfileManager.h>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/log/Log.hpp>

#include <spdlog/spdlog.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <mutex>
#include <optional>

namespace ddswarm {
namespace {

/// A partition no ddswarm writer publishes in: a reader's own subscriber
/// goes there before the reader is deleted (Participant::leave_writers).
constexpr const char* kLeavingPartition = "ddswarm/leaving";

using eprosima::fastdds::rtps::SharedMemTransportDescriptor;
using eprosima::fastdds::rtps::UDPv4TransportDescriptor;
using eprosima::fastrtps::rtps::IPLocator;
using eprosima::fastrtps::rtps::Locator_t;

constexpr const char* kLoopback = "127.0.0.1";
/// Participant ids 0..kInitialPeersRange-1 get unicast discovery pings.
constexpr int kInitialPeersRange = 120;

/// DDSWARM_FASTDDS_LOG=off|error|warning|info: how much of Fast DDS's own
/// log a process prints (to stdout). Off unless asked: ddswarm reports what
/// matters in its own words, and Fast DDS 2.9 prints errors after runs that
/// went well (under DDS Security, as a secure participant closes). Its
/// warnings name what its transports do on their own, such as a shared-memory
/// port found unhealthy and made anew (docs/dds.md).
/// Once per process, before its first participant; a bad value throws each time.
void apply_fastdds_log_env() {
  using eprosima::fastdds::dds::Log;
  static std::once_flag once;
  std::call_once(once, [] {
    const char* v = std::getenv("DDSWARM_FASTDDS_LOG");
    const std::string s = v ? v : "";
    if (s.empty() || s == "off")
      Log::ClearConsumers();
    else if (s == "error")
      Log::SetVerbosity(Log::Error);
    else if (s == "warning")
      Log::SetVerbosity(Log::Warning);
    else if (s == "info")
      Log::SetVerbosity(Log::Info);
    else
      throw DdsError("DDSWARM_FASTDDS_LOG: '" + s + "' is not one of off, error, warning, info");
  });
}

void load_profiles_once(const std::string& file) {
  static std::mutex mu;
  static std::string loaded;
  std::lock_guard<std::mutex> lock(mu);
  if (loaded == file) return;
  auto rc = fdds::DomainParticipantFactory::get_instance()->load_XML_profiles_file(file);
  if (rc != ReturnCode_t::RETCODE_OK) throw DdsError("cannot load DDS QoS profiles from " + file);
  // Participants of one process talk through their transports, as those of
  // two processes do, whatever the file says: with Fast DDS 2.9.1's
  // intraprocess delivery, a participant that closes while another in its
  // process lives on (such as a ground station's status snapshot) leaves a
  // dangling reader behind, and the process crashes on exit (docs/dds.md).
  eprosima::fastrtps::LibrarySettingsAttributes lib =
      eprosima::fastrtps::xmlparser::XMLProfileManager::library_settings();
  lib.intraprocess_delivery = eprosima::fastrtps::INTRAPROCESS_OFF;
  eprosima::fastrtps::xmlparser::XMLProfileManager::library_settings(lib);
  loaded = file;
}

Locator_t udp_locator(const std::string& ip, uint32_t port) {
  Locator_t l;
  l.kind = LOCATOR_KIND_UDPv4;
  IPLocator::setIPv4(l, ip);
  l.port = port;
  return l;
}

/// DDS Security's three built-in plugins with the role's credentials
/// (docs/security.md). Fast DDS wants absolute file:// URIs.
void add_security(const DdsConfig& cfg, fdds::DomainParticipantQos& qos) {
  const auto f = cfg.security_files();
  auto uri = [](const std::string& p) {
    return "file://" + std::filesystem::absolute(p).lexically_normal().string();
  };
  auto& props = qos.properties().properties();
  props.emplace_back("dds.sec.auth.plugin", "builtin.PKI-DH");
  props.emplace_back("dds.sec.auth.builtin.PKI-DH.identity_ca", uri(f[0]));
  props.emplace_back("dds.sec.auth.builtin.PKI-DH.identity_certificate", uri(f[4]));
  props.emplace_back("dds.sec.auth.builtin.PKI-DH.private_key", uri(f[5]));
  props.emplace_back("dds.sec.access.plugin", "builtin.Access-Permissions");
  props.emplace_back("dds.sec.access.builtin.Access-Permissions.permissions_ca", uri(f[1]));
  props.emplace_back("dds.sec.access.builtin.Access-Permissions.governance", uri(f[2]));
  props.emplace_back("dds.sec.access.builtin.Access-Permissions.permissions", uri(f[3]));
  props.emplace_back("dds.sec.crypto.plugin", "builtin.AES-GCM-GMAC");
}

/// Whether a participant for cfg adds the shared-memory transport.
bool uses_shared_memory(const DdsConfig& cfg) {
  // Not under DDS Security: over shared memory, Fast DDS 2.9's authentication
  // handshakes left a server-agent pair unauthenticated for good in 3 of 10
  // six-drone launches (0 of 18 over UDP on 127.0.0.1; docs/security.md).
  //
  // Not in the ThreadSanitizer build either: the transport's segments and
  // ports are synchronised by robust mutexes and atomics shared between
  // processes, which TSan cannot see, so it reported races inside Fast DDS's
  // unsymbolized code on every few runs (docs/sanitizers.md). Over UDP every
  // hand-off between threads is one TSan models, and our threads are the same.
#ifdef DDSWARM_TSAN_BUILD
  constexpr bool kShmAllowed = false;
#else
  constexpr bool kShmAllowed = true;
#endif
  return cfg.shared_memory && !cfg.secure() && kShmAllowed;
}

/// Whether it adds the shared-memory transport, besides data-sharing delivery.
bool uses_shm_transport(const DdsConfig& cfg) {
  return uses_shared_memory(cfg) && cfg.shm_transport;
}

/// Builds participant QoS whose every transport is bound to what cfg allows.
fdds::DomainParticipantQos make_qos(const DdsConfig& cfg, const std::string& name) {
  fdds::DomainParticipantQos qos = fdds::PARTICIPANT_QOS_DEFAULT;
  qos.name(name);
  auto& wp = qos.wire_protocol();
  wp.participant_id = cfg.participant_id;
  wp.builtin.discovery_config.leaseDuration = eprosima::fastrtps::Duration_t(cfg.lease_duration_s);
  wp.builtin.discovery_config.leaseDuration_announcementperiod = eprosima::fastrtps::Duration_t(
      cfg.announcement_period_s > 0.0 ? cfg.announcement_period_s : cfg.lease_duration_s / 3.0);

  // Never the built-in all-interfaces transports.
  qos.transport().use_builtin_transports = false;
  qos.transport().user_transports.clear();

  auto udp = std::make_shared<UDPv4TransportDescriptor>();
  udp->interfaceWhiteList.clear();
  udp->interfaceWhiteList.emplace_back(kLoopback);
  // Room for the whole swarm's state in one UDP datagram train; large samples fragment.
  udp->sendBufferSize = kUdpSocketBufferBytes;
  udp->receiveBufferSize = kUdpSocketBufferBytes;

  switch (cfg.discovery) {
    case Discovery::kLocalhost:
      // Same-host discovery: SHM multicast plus unicast pings to 127.0.0.1,
      // to every id, or only to the server's and tools' (an agent's, where
      // unicast pings are all the discovery there is).
      if ((cfg.announce_to_tools_only || !cfg.meets_agents) && !uses_shared_memory(cfg)) {
        const int ids = std::min(kAgentParticipantIdBase, max_participant_id(cfg.domain_id) + 1);
        for (int id = 0; id < ids; ++id)
          wp.builtin.initialPeersList.push_back(
              udp_locator(kLoopback, rtps_unicast_port(cfg.domain_id, id)));
        // Nor does it listen for multicast announcements, where loopback carries them.
        wp.builtin.metatrafficMulticastLocatorList.clear();
        wp.builtin.metatrafficUnicastLocatorList.push_back(udp_locator(kLoopback, 0));
      } else {
        wp.builtin.initialPeersList.push_back(udp_locator(kLoopback, 0));
      }
      break;
    case Discovery::kInterface:
      udp->interfaceWhiteList.emplace_back(cfg.interface_ip);
      break;
    case Discovery::kPeers: {
      udp->interfaceWhiteList.emplace_back(cfg.interface_ip);
      for (const auto& p : cfg.peers) {
        auto colon = p.find(':');
        uint32_t port = colon == std::string::npos ? 0 : std::stoul(p.substr(colon + 1));
        wp.builtin.initialPeersList.push_back(udp_locator(p.substr(0, colon), port));
      }
      wp.builtin.initialPeersList.push_back(udp_locator(kLoopback, 0));
      // Unicast only: no multicast announcements on the opted-in network.
      wp.builtin.metatrafficMulticastLocatorList.clear();
      wp.builtin.metatrafficUnicastLocatorList.push_back(udp_locator(cfg.interface_ip, 0));
      break;
    }
    case Discovery::kDiscoveryServer: {
      auto colon = cfg.discovery_server.find(':');
      std::string ip = cfg.discovery_server.substr(0, colon);
      uint32_t port =
          colon == std::string::npos ? 11811 : std::stoul(cfg.discovery_server.substr(colon + 1));
      // Reach a server on another host through this host's own address on
      // that network (the whitelist takes local addresses only).
      if (!cfg.interface_ip.empty()) udp->interfaceWhiteList.emplace_back(cfg.interface_ip);
      eprosima::fastrtps::rtps::RemoteServerAttributes server;
      server.ReadguidPrefix("44.53.00.5f.45.50.52.4f.53.49.4d.41");  // fast-discovery-server -i 0
      server.metatrafficUnicastLocatorList.push_back(udp_locator(ip, port));
      wp.builtin.discovery_config.discoveryProtocol =
          eprosima::fastrtps::rtps::DiscoveryProtocol_t::CLIENT;
      wp.builtin.discovery_config.m_DiscoveryServers.push_back(server);
      break;
    }
  }
  // Give the initial-peers scan room for a large swarm on one host.
  udp->maxInitialPeersRange = kInitialPeersRange;

  if (uses_shm_transport(cfg)) {
    auto shm = std::make_shared<SharedMemTransportDescriptor>();
    shm->segment_size(cfg.shm_segment_bytes);
    shm->port_queue_capacity(cfg.shm_port_queue);
    shm->healthy_check_timeout_ms(
        static_cast<uint32_t>(std::lround(cfg.shm_health_check_s * 1000.0)));
    qos.transport().user_transports.push_back(shm);
  }
  qos.transport().user_transports.push_back(udp);
  if (cfg.secure()) add_security(cfg, qos);
  return qos;
}

/// This process's participants so far: the first one's GUID prefix, and how
/// many have been made (incarnation_prefix).
struct ProcessParticipants {
  std::mutex mu;
  std::optional<eprosima::fastrtps::rtps::GuidPrefix_t> first;
  std::uint32_t made = 0;
};
ProcessParticipants& process_participants() {
  static ProcessParticipants p;
  return p;
}

/// A participant at the first free id above every agent's, where no agent
/// announces itself (DdsConfig::meets_agents; others of its kind may hold
/// some), or nullptr with qos's id automatic again: every id was taken (said
/// in a warning), or creating it failed for another reason, which the
/// caller's own attempt then names.
fdds::DomainParticipant* create_above_agents(fdds::DomainParticipantFactory* factory, int domain_id,
                                             fdds::DomainParticipantQos& qos,
                                             fdds::DomainParticipantListener* listener) {
  auto& id_in_qos = qos.wire_protocol().participant_id;
  for (const int id : participant_ids_above_agents(domain_id)) {
    if (participant_id_taken_here(domain_id, id)) continue;
    id_in_qos = id;
    if (auto* p = factory->create_participant(domain_id, qos, listener, fdds::StatusMask::none()))
      return p;
    if (!participant_id_taken_here(domain_id, id)) {  // not for want of its port
      id_in_qos = -1;
      return nullptr;
    }
  }
  spdlog::warn(
      "no participant id above the agents' is free on domain {}: this participant meets every "
      "agent",
      domain_id);
  id_in_qos = -1;
  return nullptr;
}

std::atomic<std::uint64_t> g_write_throws{0};
std::atomic<std::uint64_t> g_handler_throws{0};

/// Counts one more failure; returns the count when it deserves a log line
/// (the first, then each power of two), 0 otherwise.
std::uint64_t count_for_log(std::atomic<std::uint64_t>& failures) {
  const std::uint64_t n = ++failures;
  return std::has_single_bit(n) ? n : 0;
}

std::string topic_name(const fdds::TopicDescription* t) {
  return t ? t->get_name() : std::string("an unknown topic");
}

}  // namespace

bool participant_id_taken_here(int domain_id, int participant_id) {
  const int fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return false;
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(rtps_unicast_port(domain_id, participant_id)));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  const bool taken =
      bind(fd, reinterpret_cast<const sockaddr*>(&a), sizeof a) != 0 && errno == EADDRINUSE;
  close(fd);
  return taken;
}

bool write_threw(fdds::DataWriter* w, const std::exception& e) {
  if (const std::uint64_t n = count_for_log(g_write_throws))
    spdlog::warn(
        "a DDS write on {} threw ({} so far in this process), its sample lost; carrying on: {}",
        topic_name(w ? w->get_topic() : nullptr), n, e.what());
  return false;
}

std::uint64_t write_throws() { return g_write_throws.load(); }

void handler_threw(fdds::DataReader* r, const std::exception& e) {
  if (const std::uint64_t n = count_for_log(g_handler_throws))
    spdlog::error(
        "a sample of {} could not be handled ({} so far in this process), dropped; carrying on: {}",
        topic_name(r ? r->get_topicdescription() : nullptr), n, e.what());
}

std::uint64_t handler_throws() { return g_handler_throws.load(); }

eprosima::fastrtps::rtps::GuidPrefix_t incarnation_prefix(
    const eprosima::fastrtps::rtps::GuidPrefix_t& first, std::uint32_t n) {
  auto p = first;
  p.value[9] = static_cast<eprosima::fastrtps::rtps::octet>(n & 0xff);
  p.value[10] = static_cast<eprosima::fastrtps::rtps::octet>((n >> 8) & 0xff);
  p.value[11] = static_cast<eprosima::fastrtps::rtps::octet>((n >> 16) & 0xff);
  return p;
}

/// What this participant knows of each live remote one, by GUID: its name,
/// when it announced itself and, under DDS Security, when it authenticated.
/// Fed by Fast DDS's threads; the announcement comes before the handshake.
class PeerWatch : public fdds::DomainParticipantListener {
 public:
  using ParticipantDiscoveryInfo = eprosima::fastrtps::rtps::ParticipantDiscoveryInfo;
  using ParticipantAuthenticationInfo = eprosima::fastrtps::rtps::ParticipantAuthenticationInfo;

  void on_participant_discovery(fdds::DomainParticipant*,
                                ParticipantDiscoveryInfo&& info) override {
    const std::lock_guard<std::mutex> lock(mu_);
    const auto& guid = info.info.m_guid;
    if (info.status == ParticipantDiscoveryInfo::DISCOVERED_PARTICIPANT)
      peers_.try_emplace(guid, Peer{info.info.m_participantName.to_string(), wall_seconds(), -1.0});
    else if (info.status == ParticipantDiscoveryInfo::REMOVED_PARTICIPANT ||
             info.status == ParticipantDiscoveryInfo::DROPPED_PARTICIPANT)
      peers_.erase(guid);
  }
  void onParticipantAuthentication(fdds::DomainParticipant*,
                                   ParticipantAuthenticationInfo&& info) override {
    const std::lock_guard<std::mutex> lock(mu_);
    auto it = peers_.find(info.guid);
    if (it != peers_.end() && info.status == ParticipantAuthenticationInfo::AUTHORIZED_PARTICIPANT)
      it->second.authenticated_after_s = wall_seconds() - it->second.since;
  }

  std::vector<RemotePeer> named(const std::string& name) const {
    const std::lock_guard<std::mutex> lock(mu_);
    std::vector<RemotePeer> found;
    const double now = wall_seconds();
    for (const auto& [guid, p] : peers_)
      if (p.name == name)
        found.push_back(RemotePeer{guid.guidPrefix, now - p.since, p.authenticated_after_s});
    std::sort(found.begin(), found.end(), [](const RemotePeer& a, const RemotePeer& b) {
      return a.announced_s > b.announced_s;
    });
    return found;
  }

 private:
  struct Peer {
    std::string name;
    double since;
    double authenticated_after_s;
  };
  mutable std::mutex mu_;
  std::map<eprosima::fastrtps::rtps::GUID_t, Peer> peers_;
};

Participant::Participant(const DdsConfig& cfg, const std::string& name) {
  cfg.validate();
  apply_fastdds_log_env();
  load_profiles_once(cfg.profiles_file);
  auto* factory = fdds::DomainParticipantFactory::get_instance();
  secure_ = cfg.secure();
  shared_memory_ = uses_shared_memory(cfg);
  role_ = cfg.security_role;
  auto qos = make_qos(cfg, name);
  {
    // A new GUID for every participant of this process: Fast DDS 2.9 builds
    // the prefix from the host, the process and the participant id, so an
    // agent that leaves DDS and joins again would come back under the very
    // GUID it left with. Its discovery server would then take the new
    // participant's endpoints for the departed one's ("Writer ... has no
    // associated participant. Skipping") and never match them, and the agent
    // would have to re-join again (docs/performance.md). Under DDS Security
    // too: its authentication derives the prefix from this one, and a secure
    // agent joins under the same id every time (kAgentParticipantIdBase + K),
    // so a re-joined agent would have the departed one's GUID, and the
    // server's handshake with it would stay as stalled as the old one's.
    auto& pp = process_participants();
    std::lock_guard<std::mutex> lock(pp.mu);
    if (pp.first) qos.wire_protocol().prefix = incarnation_prefix(*pp.first, pp.made);
    // An automatic id whose shared-memory ports no process left behind:
    // otherwise a server restarted after a SIGKILL comes up on its dead
    // predecessor's ports, and the agents keep sending into the old ones
    // (shm_clean.hpp).
    const bool clear_id = cfg.participant_id < 0 && uses_shm_transport(cfg);
    if (clear_id)
      qos.wire_protocol().participant_id = participant_id_clear_of_shm(
          cfg.domain_id, std::min(kInitialPeersRange - 1, max_participant_id(cfg.domain_id)));
    // The watch hears discovery and authentication only (no data status):
    // every reader and writer keeps its own listener.
    peer_watch_ = std::make_unique<PeerWatch>();
    if (!cfg.meets_agents && cfg.participant_id < 0 && cfg.discovery == Discovery::kLocalhost &&
        !shared_memory_) {
      participant_ = create_above_agents(factory, cfg.domain_id, qos, peer_watch_.get());
      meets_agents_ = !participant_;
    }
    if (!participant_)
      participant_ = factory->create_participant(cfg.domain_id, qos, peer_watch_.get(),
                                                 fdds::StatusMask::none());
    if (!participant_ && clear_id && qos.wire_protocol().participant_id >= 0) {
      qos.wire_protocol().participant_id =
          -1;  // e.g. the id is this process's already: Fast DDS picks
      participant_ = factory->create_participant(cfg.domain_id, qos, peer_watch_.get(),
                                                 fdds::StatusMask::none());
    }
    if (participant_) {
      if (!pp.first) pp.first = participant_->guid().guidPrefix;
      ++pp.made;
    }
  }
  if (!participant_)
    throw DdsError(
        "cannot create DDS participant on domain " + std::to_string(cfg.domain_id) +
        (secure_ ? " with DDS Security as " + role_ + " (credentials in " + cfg.security_dir +
                       ": are they from one scripts/make-certs run, valid, for this domain?)"
                 : std::string()));
  publisher_ = participant_->create_publisher(fdds::PUBLISHER_QOS_DEFAULT);
  subscriber_ = participant_->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT);
  if (!publisher_ || !subscriber_) {
    participant_->delete_contained_entities();  // before its listener goes
    fdds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
    participant_ = nullptr;
    throw DdsError("cannot create DDS publisher/subscriber");
  }
}

std::vector<RemotePeer> Participant::peers_named(const std::string& name) const {
  return peer_watch_->named(name);
}

fdds::Publisher* Participant::publisher_for(const std::string& partition) {
  if (partition.empty()) return publisher_;
  std::lock_guard<std::mutex> lock(mu_);
  auto& p = partition_publishers_[partition];
  if (!p) {
    fdds::PublisherQos qos = fdds::PUBLISHER_QOS_DEFAULT;
    qos.partition().push_back(partition.c_str());
    p = participant_->create_publisher(qos);
    if (!p) throw DdsError("cannot create DDS publisher for partition " + partition);
  }
  return p;
}

fdds::Subscriber* Participant::new_subscriber(const std::string& partition) {
  fdds::SubscriberQos qos = fdds::SUBSCRIBER_QOS_DEFAULT;
  if (!partition.empty()) qos.partition().push_back(partition.c_str());
  auto* s = participant_->create_subscriber(qos);
  if (!s) throw DdsError("cannot create DDS subscriber for partition '" + partition + "'");
  return s;
}

fdds::Subscriber* Participant::subscriber_for(const std::string& partition) {
  if (partition.empty()) return subscriber_;
  std::lock_guard<std::mutex> lock(mu_);
  auto& s = partition_subscribers_[partition];
  if (!s) s = new_subscriber(partition);
  return s;
}

fdds::Subscriber* Participant::own_subscriber(const std::string& partition) {
  auto* s = new_subscriber(partition);
  std::lock_guard<std::mutex> lock(mu_);
  own_subscribers_.insert(s);
  return s;
}

bool Participant::bounded(fdds::Topic* topic) const {
  const fdds::TypeSupport ts = participant_->find_type(topic->get_type_name());
  return !ts.empty() && ts->is_bounded();
}

void Participant::leave_writers(fdds::Subscriber* s) {
  fdds::SubscriberQos qos = s->get_qos();
  qos.partition().clear();
  qos.partition().push_back(kLeavingPartition);
  if (s->set_qos(qos) != ReturnCode_t::RETCODE_OK)
    spdlog::debug(
        "dds: a reader's subscriber did not leave its writers' partition before its deletion");
}

void Participant::delete_reader(fdds::DataReader* r) {
  auto* s = const_cast<fdds::Subscriber*>(r->get_subscriber());
  bool own = false;
  {
    std::lock_guard<std::mutex> lock(mu_);
    own = own_subscribers_.erase(s) > 0;
  }
  if (own) leave_writers(s);
  s->delete_datareader(r);
  if (own) participant_->delete_subscriber(s);
}

std::string Participant::refused_hint(const std::string& partition) const {
  if (!secure_) return "";
  return " (DDS Security: does role " + role_ + "'s grant allow it" +
         (partition.empty() ? std::string() : " in partition " + partition) +
         "? see docs/security.md)";
}

void Participant::close() {
  if (participant_ && !closed_) {
    std::set<fdds::Subscriber*> own;
    {
      std::lock_guard<std::mutex> lock(mu_);
      own = own_subscribers_;
    }
    for (auto* s : own) leave_writers(s);
    participant_->delete_contained_entities();
  }
  closed_ = true;
  std::lock_guard<std::mutex> lock(mu_);
  partition_publishers_.clear();
  partition_subscribers_.clear();
  own_subscribers_.clear();
}

Participant::~Participant() {
  if (!participant_) return;
  close();
  fdds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
}

int end_process(int code) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  return code;
#else
  auto* factory = fdds::DomainParticipantFactory::get_instance();
  for (int d = 0; d <= kMaxDomainId; ++d)
    if (!factory->lookup_participants(static_cast<fdds::DomainId_t>(d)).empty()) return code;
  spdlog::shutdown();
  fdds::Log::Flush();
  std::cout.flush();
  std::cerr.flush();
  std::fflush(nullptr);
  std::_Exit(code);
#endif
}

}  // namespace ddswarm
