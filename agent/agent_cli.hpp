#pragma once
// ddswarm-agent's command line and its run: what main() parses, the config
// it builds from it (checked as the agent reads it), and the run, which joins
// DDS again as a new participant each time the join rules say so.
#include <CLI/CLI.hpp>

#include <optional>
#include <string>

#include "agent/agent_app.hpp"
#include "common/dds_config.hpp"

namespace ddswarm::agent {

struct AgentCommandLine {
  std::string config;
  std::optional<int> id;
  std::string ids_text;
  double duration_s = 0;
  std::optional<int> drones;
  double duplicate_probe_s = 1.0;
  bool check = false;
  DdsConfig dds;

  /// Adds every option to app.
  void add_to(CLI::App& app);
  /// The configuration the options and the scenario give, validated. Throws
  /// ConfigError naming the file and the field or option.
  AgentAppConfig config_for(const CLI::App& app) const;
};

/// Flies cfg's drones until a stop, duration_s of wall time (0: until a
/// stop), or a duplicate agent; joins again as the rules say. Returns the
/// exit code (0, or 3 when another agent flies a drone already).
int run_agent(const AgentAppConfig& cfg, double duration_s, int argc, char** argv);

}  // namespace ddswarm::agent
