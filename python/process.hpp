#pragma once
// Process helpers for ddswarm.launch() (python/ddswarm/launch.py).
#include <string>
#include <utility>
#include <vector>

namespace ddswarm::py_api {

/// Starts argv (argv[0] a path) in a session of its own, stdin from
/// /dev/null, stdout and stderr appended to log_path, SIGTERM to it when the
/// calling thread ends. Returns its pid; throws std::runtime_error naming
/// the program when it cannot start.
int spawn_session(const std::vector<std::string>& argv, const std::string& log_path);

/// The first DDS domain from `first` up that is unclaimed and has no live
/// participant on this host (common/domain_claim.hpp), -1 when none, and
/// one line per domain passed over. The claim is let go before returning.
std::pair<int, std::vector<std::string>> free_domain(int first);

/// Writes path with every "key.path=value" of sets applied to out, as
/// ddswarm-launch --set does. Throws ConfigError/FieldError on a bad one.
void derive_scenario(const std::string& path, const std::vector<std::string>& sets,
                     const std::string& out);

}  // namespace ddswarm::py_api
