#pragma once
// ddswarm-sim's command line and its run: what main() parses, the config it
// builds from it (checked as the server reads it), and the run, which starts
// a new server each time SIGUSR1 asks before a mission.
#include <CLI/CLI.hpp>

#include <cstdint>
#include <optional>
#include <string>

#include "common/dds_config.hpp"
#include "sim_server/sim_server.hpp"

namespace ddswarm::sim {

struct SimCommandLine {
  std::string scenario;
  double duration_s = 0;
  std::optional<std::uint64_t> seed;
  std::optional<int> drones;
  std::optional<std::string> mode;
  bool check = false;
  DdsConfig dds;

  /// Adds every option to app.
  void add_to(CLI::App& app);
  /// The configuration the scenario and the options give, validated. Throws
  /// ConfigError naming the file and the field or option.
  ServerConfig config_for(const CLI::App& app) const;
};

/// Clears the zombie shared-memory files, then serves cfg's swarm until a
/// stop or duration_s of wall time (0: until a stop), joining again as a new
/// server each time SIGUSR1 asks. Returns the exit code: 0, or 3 when another
/// server holds the domain.
int run_sim(const ServerConfig& cfg, double duration_s);

}  // namespace ddswarm::sim
