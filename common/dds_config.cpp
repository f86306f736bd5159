#include "common/dds_config.hpp"

#include <arpa/inet.h>
#include <CLI/CLI.hpp>
#include <algorithm>

#include <ifaddrs.h>
#include <netinet/in.h>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "common/scenario.hpp"
#include "common/yaml_section.hpp"

namespace ddswarm {
namespace {
bool is_ipv4(const std::string& s) {
  in_addr a{};
  return inet_pton(AF_INET, s.c_str(), &a) == 1;
}
std::string host_of(const std::string& s) { return s.substr(0, s.find(':')); }
/// True when ip is assigned to one of this host's interfaces.
bool is_local_address(const std::string& ip) {
  in_addr want{};
  if (inet_pton(AF_INET, ip.c_str(), &want) != 1) return false;
  ifaddrs* list = nullptr;
  if (getifaddrs(&list) != 0) return false;
  bool found = false;
  for (ifaddrs* a = list; a && !found; a = a->ifa_next)
    if (a->ifa_addr && a->ifa_addr->sa_family == AF_INET)
      found = reinterpret_cast<sockaddr_in*>(a->ifa_addr)->sin_addr.s_addr == want.s_addr;
  freeifaddrs(list);
  return found;
}
}  // namespace

void load(YamlSection s, DdsConfig& c) {
  FieldLoader load(s);
  DdsConfig::fields(c, load);
  c.lease_named = s.has("lease_duration_s");
  s.finish();
}

int rtps_unicast_port(int domain_id, int participant_id) {
  return rtps_port_base(domain_id) + 10 + 2 * participant_id;
}
PortRange ephemeral_port_range() {
  PortRange r;
  std::ifstream("/proc/sys/net/ipv4/ip_local_port_range") >> r.lo >> r.hi;
  return r;
}

int max_participant_id(int domain_id) { return (65535 - 1 - rtps_unicast_port(domain_id, 0)) / 2; }

std::vector<int> participant_ids_above_agents(int domain_id) {
  constexpr int kAboveEveryAgent = kAgentParticipantIdBase + kMaxDrones;
  std::vector<int> ids;
  for (int id = max_participant_id(domain_id);
       id >= kAboveEveryAgent && static_cast<int>(ids.size()) < kAboveAgentsIds; --id)
    ids.push_back(id);
  return ids;
}

std::uint32_t agent_shm_segment_bytes(std::size_t drones) {
  const std::size_t bytes = (256u << 10) + drones * (16u << 10);
  return static_cast<std::uint32_t>(std::min<std::size_t>(bytes, kShmSegmentBytes));
}

std::uint32_t agent_shm_port_queue(std::size_t drones) {
  return static_cast<std::uint32_t>(std::clamp<std::size_t>(16 * drones, 512, kShmPortQueue));
}

DdsConfig one_shot(DdsConfig c) {
  if (!(c.announcement_period_s > 0.0)) c.announcement_period_s = c.lease_duration_s / 3.0;
  c.lease_duration_s = std::max(c.lease_duration_s, kOneShotLeaseS);
  return c;
}

void DdsConfig::validate() const {
  if (FILE* f = std::fopen(profiles_file.c_str(), "r")) {
    std::fclose(f);
  } else {
    throw FieldError("dds.profiles_file", profiles_file, "cannot read this file");
  }
  FieldChecker check("dds");
  fields(*this, check);
  // RTPS ports: 7400 + 250 * domain + 11 + 2 * participant_id must stay below 65536.
  check_range("dds.participant_id", participant_id, -1, max_participant_id(domain_id));
  if (!(announcement_period_s >= 0.0 && announcement_period_s < lease_duration_s))
    throw FieldError("dds.announcement_period_s", to_text(announcement_period_s),
                     "must be 0 (a third of the lease) or less than dds.lease_duration_s");
  if (discovery == Discovery::kInterface || discovery == Discovery::kPeers) {
    if (!is_ipv4(interface_ip))
      throw FieldError("dds.interface_ip", interface_ip.empty() ? "(empty)" : interface_ip,
                       "must be this host's IPv4 address on the chosen network");
  }
  if (discovery == Discovery::kPeers) {
    if (peers.empty()) throw FieldError("dds.peers", "(empty)", "list at least one peer address");
    for (const auto& p : peers)
      if (!is_ipv4(host_of(p))) throw FieldError("dds.peers", p, "must be an IPv4 address");
  }
  if (discovery == Discovery::kDiscoveryServer) {
    if (!is_ipv4(host_of(discovery_server)))
      throw FieldError("dds.discovery_server",
                       discovery_server.empty() ? "(empty)" : discovery_server, "must be ip:port");
    if (host_of(discovery_server) != "127.0.0.1" && interface_ip.empty())
      throw FieldError(
          "dds.interface_ip", "(empty)",
          "a discovery server on another host needs this host's address on that network "
          "(--dds-local-ip)");
  }
  if (secure() && discovery == Discovery::kDiscoveryServer)
    throw FieldError("dds.discovery_server", discovery_server,
                     "cannot be used with DDS Security (--secure): Fast DDS 2.9 has no secure "
                     "discovery server (docs/security.md)");
  if (secure()) {
    if (security_role.empty() ||
        security_role.find_first_not_of(
            "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-") !=
            std::string::npos)
      throw FieldError(
          "dds.security_role", security_role.empty() ? "(empty)" : security_role,
          "must name an identity made by scripts/make-certs, e.g. server, gs, recorder, agent-3");
    std::string missing;
    for (const auto& f : security_files()) {
      std::error_code ec;
      if (!std::filesystem::is_regular_file(f, ec))
        missing += (missing.empty() ? "" : ", ") + std::filesystem::path(f).filename().string();
    }
    if (!missing.empty())
      throw FieldError("dds.secure", security_dir,
                       "missing " + missing + " for role " + security_role +
                           " (make them with scripts/make-certs --out " + security_dir + ")");
  }
  // Fast DDS silently drops a whitelisted address this host does not have,
  // which would leave the process unreachable without a word.
  if (!interface_ip.empty() && discovery != Discovery::kLocalhost &&
      !is_local_address(interface_ip))
    throw FieldError("dds.interface_ip", interface_ip, "is not an address of this host");
}

std::vector<std::string> DdsConfig::security_files() const {
  const std::string d = security_dir + "/";
  return {d + "identity_ca.cert.pem",
          d + "permissions_ca.cert.pem",
          d + "governance.p7s",
          d + security_role + ".permissions.p7s",
          d + security_role + ".cert.pem",
          d + security_role + ".key.pem"};
}

void default_security_role(DdsConfig& c, const std::string& role) {
  if (c.security_role.empty()) c.security_role = role;
}

std::string drone_partition(int drone_id) { return "drone/" + std::to_string(drone_id); }

void add_dds_options(CLI::App& app, DdsConfig& c) {
  app.add_option("--domain", c.domain_id, "DDS domain id (0-232)");
  app.add_option_function<std::string>(
         "--dds-interface",
         [&c](const std::string& ip) {
           c.discovery = Discovery::kInterface;
           c.interface_ip = ip;
         },
         "opt in to another network: this host's IPv4 address on it (multicast discovery there)")
      ->group("Networking (default: this machine only)");
  app.add_option_function<std::vector<std::string>>(
         "--dds-peers",
         [&c](const std::vector<std::string>& p) {
           c.discovery = Discovery::kPeers;
           c.peers = p;
         },
         "opt in: unicast discovery to these peer IPv4 addresses (needs --dds-local-ip)")
      ->delimiter(',')
      ->group("Networking (default: this machine only)");
  app.add_option(
         "--dds-local-ip", c.interface_ip,
         "with --dds-peers or a remote --discovery-server: this host's address on that network")
      ->group("Networking (default: this machine only)");
  app.add_option_function<std::string>(
         "--discovery-server",
         [&c](const std::string& s) {
           c.discovery = Discovery::kDiscoveryServer;
           c.discovery_server = s;
         },
         "use a Fast DDS discovery server at ip:port")
      ->group("Networking (default: this machine only)");
  app.add_option("--dds-profiles", c.profiles_file, "QoS profiles XML")
      ->group("Networking (default: this machine only)");
  app.add_option("--participant-id", c.participant_id, "RTPS participant id (-1 automatic)")
      ->group("Networking (default: this machine only)");
  app.add_flag("--best-effort-streams", c.best_effort_streams,
               "real time: the server reads commands and agents read the swarm state best-effort "
               "(dds.best_effort_streams, default on; =false reads them reliably)")
      ->group("Networking (default: this machine only)");
  app.add_option(
         "--secure", c.security_dir,
         "DDS Security: authenticate, access-control and encrypt with the credentials in DIR "
         "(made by scripts/make-certs)")
      ->type_name("DIR")
      ->group("Security (docs/security.md)");
  app.add_option("--security-role", c.security_role,
                 "with --secure: the identity to use (default: this program's role)")
      ->type_name("NAME")
      ->group("Security (docs/security.md)");
}

}  // namespace ddswarm

namespace ddswarm {
void merge_cli(DdsConfig& target, const DdsConfig& cli, const CLI::App& app) {
  if (app.count("--domain")) target.domain_id = cli.domain_id;
  if (app.count("--dds-interface") || app.count("--dds-peers") || app.count("--discovery-server")) {
    target.discovery = cli.discovery;
    target.peers = cli.peers;
    target.discovery_server = cli.discovery_server;
  }
  if (app.count("--dds-interface") || app.count("--dds-local-ip"))
    target.interface_ip = cli.interface_ip;
  if (app.count("--dds-profiles")) target.profiles_file = cli.profiles_file;
  if (app.count("--participant-id")) target.participant_id = cli.participant_id;
  if (app.count("--best-effort-streams")) target.best_effort_streams = cli.best_effort_streams;
  if (app.count("--secure")) target.security_dir = cli.security_dir;
  if (app.count("--security-role")) target.security_role = cli.security_role;
  secure_lease(target);
}

void secure_lease(DdsConfig& c) {
  if (c.secure() && c.discovery == Discovery::kLocalhost && !c.lease_named)
    c.lease_duration_s = kSecureLeaseS;
}
}  // namespace ddswarm
