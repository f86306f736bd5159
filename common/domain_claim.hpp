#pragma once
// Which DDS domains a whole swarm may use on this host. Two swarms on one
// domain are one swarm in two worlds: the ground station of one commands the
// other's drones. A server refuses a rival on its domain once its swarm flies
// (sim_server), but an experiment starts a fresh swarm every few seconds, and
// two experiments on one host failed each other's runs (docs/faults.md).
//
// A process that runs whole swarms (ddswarm-gs experiment, ddswarm-launch with
// its server) claims each domain it uses: an flock on
// <dir>/ddswarm_domain_<N>.lock, held while the process lives (the kernel lets
// go when it dies, even by SIGKILL), with its pid and command line written in
// for whoever finds it taken. Children do not inherit it.
#include <string>
#include <vector>

namespace ddswarm {

class DomainClaim {
 public:
  /// Tries to claim domain_id; held() says whether it did. Never throws.
  explicit DomainClaim(int domain_id, const std::string& dir = "/dev/shm");
  ~DomainClaim();
  DomainClaim(DomainClaim&& other) noexcept;
  DomainClaim& operator=(DomainClaim&& other) noexcept;
  DomainClaim(const DomainClaim&) = delete;
  DomainClaim& operator=(const DomainClaim&) = delete;

  int domain() const { return domain_; }
  bool held() const { return fd_ >= 0; }
  /// When not held: who holds it, as its claimer wrote ("pid 123: ddswarm-gs
  /// experiment ..."), or why it could not be claimed.
  const std::string& holder() const { return holder_; }

 private:
  int domain_ = -1;
  int fd_ = -1;
  std::string holder_;
};

/// Claims count domains for whole swarms, from first upward (to kMaxDomainId):
/// each one unclaimed and without live participants on this host
/// (domain_has_live_participants, common/shm_clean.hpp). Fewer than count
/// when the range runs out. why_skipped, if given, gets one line per domain
/// passed over ("domain 0: pid 123: ddswarm-gs experiment ...").
std::vector<DomainClaim> claim_free_domains(int first, int count,
                                            std::vector<std::string>* why_skipped = nullptr,
                                            const std::string& dir = "/dev/shm");

}  // namespace ddswarm
